"""Re-rooting (attach `child:` other than the child model's root, and make_root; ir/reroot.py)
on example-robot-data's TALOS arm, UR5 and Panda, checked with Pinocchio: the mass, the centre
of mass and every link's pose relative to the new root at random configurations (same joint
values by name; a link on the way has the frame of the joint it had to its child), and what
each link holds, exactly."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from mpc.backends.urdf_reader import read
from mpc.backends.urdf_writer import to_string
from mpc.core.diagnostics import Sink
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.reroot import RerootError, reroot
from mpc.ir.robot import Pose
from mpc.ir.tree import joints_up
from tests.conftest import ERD, write
from tests.mpc_command import mpc

ARM = ERD / "talos_data/robots/talos_left_arm.urdf"
UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"
CASES = [(ARM, "arm_left_5_link"), (UR5, "wrist_2_link"), (ERD / "panda_description/urdf/panda.urdf",
                                                           "panda_link4")]


def _state(model: object, values: dict[str, float]) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Each link's pose and the centre of mass at the joint values (by name; base at identity)."""
    import pinocchio as pin

    q = pin.neutral(model)
    for jid in range(2, model.njoints):  # 1: the free flyer
        if model.joints[jid].nq == 1:
            q[model.joints[jid].idx_q] = values[model.names[jid]]
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    poses = {f.name: data.oMf[i].homogeneous for i, f in enumerate(model.frames) if f.type == pin.BODY}
    return poses, pin.centerOfMass(model, data, q)


@pytest.mark.parametrize(("source", "root"), CASES, ids=lambda c: getattr(c, "stem", c))
def test_reroot_keeps_the_robot(tmp_path: Path, source: Path, root: str) -> None:
    import pinocchio as pin

    robot = read(source, Sink())
    assert robot is not None
    rerooted = reroot(robot, root)
    urdf = tmp_path / "r.urdf"
    urdf.write_text(to_string(rerooted, lambda mesh: "m.stl"))
    free = pin.JointModelFreeFlyer()
    before, after = pin.buildModelFromUrdf(str(source), free), pin.buildModelFromUrdf(str(urdf), free)
    assert abs(pin.computeTotalMass(before) - pin.computeTotalMass(after)) <= 1e-12
    # A_P: a link on the way gets the frame of the joint it had to its child
    moved = {j.parent: pose_matrix(j.origin) for j in joints_up(robot, root)}
    rng = np.random.default_rng(7)
    for _ in range(5):
        values = {before.names[j]: float(rng.uniform(-1.5, 1.5)) for j in range(2, before.njoints)}
        (old, old_com), (new, new_com) = _state(before, values), _state(after, values)
        X_NW = np.linalg.inv(old[root])
        assert old.keys() == new.keys()
        for name, X in old.items():
            assert np.allclose(X_NW @ X @ moved.get(name, np.eye(4)), new[name], atol=1e-12), name
        assert np.allclose((X_NW @ np.r_[old_com, 1.0])[:3], new_com, atol=1e-12)
    X_RN = link_in_root(robot, root)  # what each link holds, in the new root, at q = 0
    for name, link in robot.links.items():
        was = np.linalg.inv(X_RN) @ link_in_root(robot, name)
        now = link_in_root(rerooted, name)
        held = [(a.origin, b.origin) for a, b in zip((*link.visuals, *link.collisions),
                                                      (*rerooted.links[name].visuals,
                                                       *rerooted.links[name].collisions), strict=True)]
        if link.inertial is not None:
            held.append((link.inertial.origin, rerooted.links[name].inertial.origin))  # type: ignore[union-attr]
        for a, b in held:
            assert np.allclose(was @ pose_matrix(a), now @ pose_matrix(b), atol=1e-12)


def test_a_sensor_on_a_moved_link_is_refused() -> None:
    from mpc.ir.extras import Sensor

    robot = read(ARM, Sink())
    assert robot is not None
    sensors = {"cam": Sensor(name="cam", type="CameraSensor", link="arm_left_3_link")}
    with pytest.raises(RerootError, match="the sensor 'cam' is placed in the frame of arm_left_3_link, "
                       "which re-rooting moves; mpc does not re-express it"):
        reroot(replace(robot, sensors=sensors), "arm_left_5_link")


def test_attach_at_a_link_other_than_the_root(tmp_path: Path) -> None:
    """The TALOS arm hung from the UR5's tool0 by its fifth link: `mpc check` knows the reversed
    joints, and the compiled robot has the arm as re-rooted there, below tool0."""
    import pinocchio as pin

    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: both
          modelname: both_model
          input_models:
            ur5: {{basefile: "{UR5}"}}
            arm: {{basefile: "{ARM}"}}
          assemble:
            model: ur5
            children:
              - model: arm
                joint: {{parent: tool0, child: arm_left_5_link, name: mount, xyz: [0, 0, 0.1]}}
        """)
    assert mpc("check", spec).returncode == 0
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    urdf = tmp_path / "out/urdf/both.urdf"
    joints = {j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))
              for j in etree.parse(str(urdf)).getroot().findall("joint")}
    assert joints["mount"] == ("tool0", "arm_left_5_link")
    assert joints["arm_left_5_joint"] == ("arm_left_5_link", "arm_left_4_link")
    assert joints["arm_left_2_joint"] == ("arm_left_2_link", "arm_left_1_link")
    free = pin.JointModelFreeFlyer()
    both, ur5, arm = (pin.buildModelFromUrdf(str(p), free) for p in (urdf, UR5, ARM))
    assert abs(pin.computeTotalMass(both) - pin.computeTotalMass(ur5) - pin.computeTotalMass(arm)) <= 1e-12
    values = {both.names[j]: 0.3 * ((-1) ** j) for j in range(2, both.njoints)}
    new, _ = _state(both, values)
    old, _ = _state(arm, {n: values[n] for n in arm.names[2:]})
    X_T = new["tool0"] @ pose_matrix(Pose(xyz=(0.0, 0.0, 0.1)))  # the mount joint's origin
    X_NW = np.linalg.inv(old["arm_left_5_link"])
    for name in ("arm_left_5_link", "arm_left_6_link", "gripper_left_fingertip_1_link"):
        assert np.allclose(X_T @ X_NW @ old[name], new[name], atol=1e-12), name
