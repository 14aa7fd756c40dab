"""MJCF input models across formats, through `mpc compile`: an MJCF arm attached to a URDF
base with a prefix, mirrored, cut with remove_beyond and take_leaf, at the start of a
derived_base chain, and exported to URDF, SDF, SMURF and MJCF. Physical checks: the arm's
bodies, relative to its root, are where MuJoCo's compiled original puts them (the mirrored
one: their mirror images at −q), in Pinocchio (URDF) and in MuJoCo (MJCF)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from tests.backends.mjcf_compare import configurations, original_poses
from tests.conftest import write
from tests.mpc_command import mpc

ARM = """
<mujoco model="arm">
  <compiler angle="radian" autolimits="true"/>
  <worldbody>
    <body name="shoulder" pos="0 0 0.1">
      <geom type="box" size="0.05 0.05 0.05" mass="1"/>
      <body name="upper" pos="0 0 0.1" euler="0 0 0.4">
        <joint name="j1" axis="0 1 0" range="-1.5 1.5" pos="0 0.02 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/>
        <body name="fore" pos="0 0 0.3" quat="0.9 0.1 0.3 0">
          <joint name="j2" axis="1 0 0" range="-1 2"/>
          <joint name="j3" type="slide" axis="0 0 1" range="0 0.1"/>
          <geom type="cylinder" size="0.02 0.1" pos="0 0 0.1"/>
          <body name="hand" pos="0.05 0 0.2">
            <joint name="j4" axis="0 0 1" range="-3 3"/>
            <geom type="box" size="0.02 0.03 0.04" pos="0.05 0 0" euler="0.1 0.2 0.3"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

BASE = """
<robot name="base">
  <link name="base">
    <inertial><mass value="5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><box size="0.4 0.6 0.1"/></geometry></visual>
  </link>
</robot>
"""

EXPORTS = """
          export_config:
            - type: urdf
            - type: sdf
            - type: smurf
            - type: mjcf
"""  # indented as the definitions below, which `write` dedents

M = np.diag([1.0, -1.0, 1.0])  # the mirror at the plane y = 0, and the flip of the frames' y axis


def _arm(tmp_path: Path) -> mujoco.MjModel:
    write(tmp_path / "arm.xml", ARM)
    write(tmp_path / "base.urdf", BASE)
    return mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml"))


def _compile(definition: Path) -> subprocess.CompletedProcess[str]:
    result = mpc("compile", definition, "-o", definition.parent / f"out_{definition.stem}")
    assert result.returncode == 0, result.stderr
    return result


def _pinocchio(urdf: Path) -> tuple[pin.Model, pin.Data]:
    model = pin.buildModelFromUrdf(str(urdf))
    return model, model.createData()


def _pin_poses(model: pin.Model, data: pin.Data, q: dict[str, float], names: list[str], root: str
               ) -> dict[str, np.ndarray]:
    x = pin.neutral(model)
    for name, value in q.items():
        jid = model.getJointId(name)
        x[model.idx_qs[jid]] = value
    pin.framesForwardKinematics(model, data, x)
    body = pin.FrameType.BODY
    inverse = np.linalg.inv(data.oMf[model.getFrameId(root, body)].homogeneous)
    return {n: inverse @ data.oMf[model.getFrameId(n, body)].homogeneous for n in names}


def _mj_poses(model: mujoco.MjModel, q: dict[str, float], names: list[str], root: str
              ) -> dict[str, np.ndarray]:
    data = mujoco.MjData(model)
    for name, value in q.items():
        data.qpos[model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)]] = value
    mujoco.mj_kinematics(model, data)

    def pose(name: str) -> np.ndarray:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = data.xmat[b].reshape(3, 3), data.xpos[b]
        return X

    inverse = np.linalg.inv(pose(root))
    return {n: inverse @ pose(n) for n in names}


def test_an_mjcf_arm_on_a_urdf_base_with_a_prefix_and_mirrored(tmp_path: Path) -> None:
    original = _arm(tmp_path)
    write(tmp_path / "combo.yml", """
        model:
          robotname: combo
          modelname: combo
          input_models:
            base: {basefile: base.urdf}
            arm: {basefile: arm.xml}
          assemble:
            model: base
            children:
              - model: arm
                name_editing: {prefix: "left_"}
                joint: {parent: base, xyz: [0, 0.2, 0.1]}
              - model: arm
                name_editing: {prefix: "right_"}
                mirror: {}
                joint: {parent: base, xyz: [0, -0.2, 0.1]}""" + EXPORTS)
    _compile(tmp_path / "combo.yml")
    out = tmp_path / "out_combo"
    assert (out / "smurf" / "combo.smurf").is_file() and (out / "sdf" / "combo.sdf").is_file()
    names = ["shoulder", "upper", "fore", "hand"]
    model, data = _pinocchio(out / "urdf" / "combo.urdf")
    written = mujoco.MjModel.from_xml_path(str(out / "mjcf" / "combo.xml"))
    assert abs(sum(i.mass for i in model.inertias) - 5 - 2 * float(np.sum(original.body_mass))) <= 1e-9
    for q in configurations(original, 5):
        expected = original_poses(original, q)
        left = {f"left_{n}": v for n, v in q.items()}
        # the mirror's revolute joints at −q, its prismatic ones at +q (specs/mirror.md)
        right = {f"right_{n}": (v if n == "j3" else -v) for n, v in q.items()}
        for got in (_pin_poses(model, data, left | right, [f"left_{n}" for n in names] +
                               [f"right_{n}" for n in names], "base"),
                    _mj_poses(written, left | right, [f"left_{n}" for n in names] +
                              [f"right_{n}" for n in names], "base")):
            for n in names:
                left_in_root = np.linalg.inv(got["left_shoulder"]) @ got[f"left_{n}"]
                np.testing.assert_allclose(left_in_root, expected[n], atol=1e-9, err_msg=n)
                right_in_root = np.linalg.inv(got["right_shoulder"]) @ got[f"right_{n}"]
                mirrored = expected[n].copy()
                mirrored[:3, :3], mirrored[:3, 3] = M @ expected[n][:3, :3] @ M, M @ expected[n][:3, 3]
                np.testing.assert_allclose(right_in_root, mirrored, atol=1e-9, err_msg=n)


def test_an_mjcf_robot_cut_and_derived(tmp_path: Path) -> None:
    """remove_beyond and take_leaf on an MJCF input, and a derived_base chain that starts from it."""
    original = _arm(tmp_path)
    write(tmp_path / "cut.yml", """
        model:
          robotname: cut
          modelname: cut
          input_models:
            arm: {basefile: arm.xml}
          assemble:
            model: arm
            take_leaf: upper
            remove_beyond: fore""" + EXPORTS)
    write(tmp_path / "derived.yml", """
        model:
          robotname: derived
          modelname: derived
          input_models:
            cut: {derived_base: cut.yml}
          assemble:
            model: cut
            name_editing: {prefix: "d_"}
          export_config:
            - type: urdf
        """)
    _compile(tmp_path / "cut.yml")
    _compile(tmp_path / "derived.yml")
    model, data = _pinocchio(tmp_path / "out_cut" / "urdf" / "cut.urdf")
    assert [f.name for f in model.frames if f.type == pin.FrameType.BODY] == ["upper", "fore__j2", "fore"]
    derived, _ = _pinocchio(tmp_path / "out_derived" / "urdf" / "derived.urdf")
    bodies = [f.name for f in derived.frames if f.type == pin.FrameType.BODY]
    assert bodies == ["d_upper", "d_fore__j2", "d_fore"]
    written = mujoco.MjModel.from_xml_path(str(tmp_path / "out_cut" / "mjcf" / "cut.xml"))
    for q in configurations(original, 5):
        expected = original_poses(original, q)
        wanted = np.linalg.inv(expected["upper"]) @ expected["fore"]
        q = {n: v for n, v in q.items() if n in ("j2", "j3")}
        for got in (_pin_poses(model, data, q, ["fore"], "upper"), _mj_poses(written, q, ["fore"], "upper")):
            np.testing.assert_allclose(got["fore"], wanted, atol=1e-9)


@pytest.mark.parametrize("command", ["check", "compile"])
def test_mjcf_errors_reach_the_command_line(tmp_path: Path, command: str) -> None:
    write(tmp_path / "bad.xml", """
        <mujoco>
          <worldbody>
            <body name="a"><joint rnge="1 2"/></body>
          </worldbody>
        </mujoco>""")
    write(tmp_path / "r.yml", """
        model:
          robotname: r
          modelname: r
          input_models:
            a: {basefile: bad.xml}
          assemble:
            model: a
          export_config:
            - type: urdf
        """)
    args = (command, tmp_path / "r.yml") + (("-o", tmp_path / "out") if command == "compile" else ())
    result = mpc(*args)
    assert result.returncode == 1
    assert (f"{tmp_path / 'bad.xml'}:3:33: error[E0440]: MuJoCo refuses '{tmp_path / 'bad.xml'}': "
            "Schema violation: unrecognized attribute: 'rnge'") in result.stdout + result.stderr
