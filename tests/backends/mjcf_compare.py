"""Physical equality of an MJCF original (MuJoCo's compiled model) and mpc's outputs of it:
its URDF in Pinocchio, its MJCF in MuJoCo. Compared: total mass, each body's world pose at
q = 0 and at random configurations of the hinges and slides, and the joint ranges.

A body's IR link frame sits at its last joint's anchor (backends/mjcf_reader.py); the
original's body frame is moved there before comparing. Poses are compared relative to the
root link (a floating root is placed by its free joint in the original, at the origin in
the outputs).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from mpc.ir.transforms import quat_to_matrix  # the MJCF reader's quaternion → matrix

HINGE, SLIDE, FREE = 3, 2, 0


def _X(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = quat_to_matrix(np.asarray(quat)), pos
    return X


def _name(m: mujoco.MjModel, b: int) -> str:
    return "world" if b == 0 else (m.body(b).name or f"body{b}")


def _joint_name(m: mujoco.MjModel, j: int) -> str:
    return m.joint(j).name or f"{_name(m, int(m.jnt_bodyid[j]))}_joint{j}"


def movable(m: mujoco.MjModel) -> list[int]:
    return [j for j in range(m.njnt) if m.jnt_type[j] in (HINGE, SLIDE)]


def configurations(m: mujoco.MjModel, n: int, seed: int = 7) -> list[dict[str, float]]:
    """q = 0 and n random values of every hinge and slide (within its range when limited)."""
    rng = np.random.default_rng(seed)
    out = [{_joint_name(m, j): 0.0 for j in movable(m)}]
    for _ in range(n):
        q = {}
        for j in movable(m):
            if m.jnt_limited[j]:
                low, high = _range(m, j)
            else:
                low, high = (-np.pi, np.pi) if m.jnt_type[j] == HINGE else (-1.0, 1.0)
            q[_joint_name(m, j)] = float(rng.uniform(low, high))
        out.append(q)
    return out


def _range(m: mujoco.MjModel, j: int) -> np.ndarray:
    """The joint's range from its `ref` (the IR's zero; most joints have ref 0)."""
    return m.jnt_range[j] - m.qpos0[m.jnt_qposadr[j]]


def _root(m: mujoco.MjModel) -> int:
    top = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
    joints = [m.jnt_type[j] for j in range(m.njnt) if m.jnt_bodyid[j] == top[0]] if len(top) == 1 else None
    floating = joints in ([FREE], [])
    return top[0] if floating else 0


def original_poses(m: mujoco.MjModel, q: dict[str, float]) -> dict[str, np.ndarray]:
    """Each body's IR frame relative to the root, in the original at q."""
    d = mujoco.MjData(m)
    d.qpos[:] = m.qpos0
    for j in movable(m):
        d.qpos[m.jnt_qposadr[j]] += q[_joint_name(m, j)]  # the IR's zero is MuJoCo's ref (qpos0)
    mujoco.mj_kinematics(m, d)
    out = {}
    for b in range(m.nbody):
        joints = [j for j in movable(m) if m.jnt_bodyid[j] == b]
        shift = np.eye(4)
        if joints:
            shift[:3, 3] = m.jnt_pos[joints[-1]]
        out[_name(m, b)] = _X(d.xpos[b], d.xquat[b]) @ shift
    root = out[_name(m, _root(m))]
    return {n: np.linalg.inv(root) @ X for n, X in out.items()}


def assert_urdf_matches(original: mujoco.MjModel, urdf: Path, n_random: int = 10, tol: float = 1e-9) -> None:
    import pinocchio as pin

    floating = _root(original) != 0
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer()) if floating \
        else pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    # every body's mass, the universe's (what a fixed base welds to it) included
    assert abs(sum(i.mass for i in model.inertias) - float(np.sum(original.body_mass))) <= tol
    for j in movable(original):
        jid = model.getJointId(_joint_name(original, j))
        assert jid < model.njoints, _joint_name(original, j)
        if original.jnt_limited[j]:
            i = model.idx_qs[jid]
            np.testing.assert_allclose([model.lowerPositionLimit[i], model.upperPositionLimit[i]],
                                       _range(original, j), atol=tol, rtol=0)
    for q in configurations(original, n_random):
        x = pin.neutral(model)
        for name, value in q.items():
            jid = model.getJointId(name)
            i = model.idx_qs[jid]
            if model.nqs[jid] == 2:  # a continuous joint: cos, sin
                x[i:i + 2] = np.cos(value), np.sin(value)
            else:
                x[i] = value
        pin.framesForwardKinematics(model, data, x)
        expected = original_poses(original, q)
        body = pin.FrameType.BODY  # a joint may have its body's name (MuJoCo's namespaces are apart)
        root = np.linalg.inv(data.oMf[model.getFrameId(_name(original, _root(original)), body)].homogeneous)
        for name, X in expected.items():
            if name == "world" and floating:
                continue
            got = root @ data.oMf[model.getFrameId(name, body)].homogeneous
            np.testing.assert_allclose(got, X, atol=tol, rtol=0, err_msg=name)


def assert_mjcf_matches(original: mujoco.MjModel, xml: Path, n_random: int = 10, tol: float = 1e-9) -> None:
    out = mujoco.MjModel.from_xml_path(str(xml))
    assert abs(float(np.sum(out.body_mass)) - float(np.sum(original.body_mass))) <= tol
    d = mujoco.MjData(out)
    for j in movable(original):
        k = mujoco.mj_name2id(out, mujoco.mjtObj.mjOBJ_JOINT, _joint_name(original, j))
        assert k >= 0, _joint_name(original, j)
        if original.jnt_limited[j]:
            np.testing.assert_allclose(out.jnt_range[k], _range(original, j), atol=tol, rtol=0)
    root_name = _name(original, _root(original))
    for q in configurations(original, n_random):
        d.qpos[:] = out.qpos0
        for name, value in q.items():
            d.qpos[out.jnt_qposadr[mujoco.mj_name2id(out, mujoco.mjtObj.mjOBJ_JOINT, name)]] = value
        mujoco.mj_kinematics(out, d)

        def pose(name: str) -> np.ndarray:
            b = 0 if name == "world" else mujoco.mj_name2id(out, mujoco.mjtObj.mjOBJ_BODY, name)
            assert b >= 0, name
            return _X(d.xpos[b], d.xquat[b])

        root = np.linalg.inv(pose(root_name))
        for name, X in original_poses(original, q).items():
            if name == "world" and root_name != "world":
                continue
            np.testing.assert_allclose(root @ pose(name), X, atol=tol, rtol=0, err_msg=name)
