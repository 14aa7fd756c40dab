"""Submodel options that merge joints (remove_fixed, remove_joints, abstract_model), filename,
and the joint_limits selections ABSTRACT and `<submodel name>`, on TALOS with Pinocchio."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml

from mpc.core.diagnostics import Severity
from tests.backends.test_submodel import HEAD
from tests.conftest import Diags, compile_file, write

GRIPPER = ["gripper_left_joint", "gripper_left_inner_double_joint", "gripper_left_fingertip_1_joint",
           "gripper_left_fingertip_2_joint", "gripper_left_motor_single_joint",
           "gripper_left_inner_single_joint", "gripper_left_fingertip_3_joint"]
# The left gripper as HyRoDyn sees it: one closed mechanism, driven by gripper_left_joint,
# which the six mimic joints follow.
SUBMECHANISMS = f"""
  submechanisms:
    - name: gripper_left
      type: 1R
      contextual_name: gripper_left
      jointnames_spanningtree: {GRIPPER}
      jointnames_independent: [gripper_left_joint]
      jointnames_active: [gripper_left_joint]
"""


def centroidal(urdf: Path) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, COM and centroidal inertia (about the COM) at q = 0 with Pinocchio."""
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    q = pin.neutral(model)
    pin.ccrba(model, data, q, np.zeros(model.nv))
    return pin.computeTotalMass(model), pin.centerOfMass(model, data, q), data.Ig.inertia.copy()


def joints_of(urdf: Path) -> dict[str, str]:
    from lxml import etree

    return {j.get("name"): j.get("type") for j in etree.parse(str(urdf)).getroot().iterfind("joint")}


def test_remove_fixed_keeps_every_joint_body(tmp_path: Path, diags: Diags) -> None:
    """The left arm with remove_fixed: no fixed joint is left, the links they carried are
    gone, and each movable joint's body has the mass, COM and inertia Pinocchio gives it in
    the whole robot (where it merges fixed links itself)."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: urdf}
    - {type: submodel, name: arm, start: arm_left_1_link, remove_fixed: true}
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    urdf = out / "submodels/arm/urdf/arm.urdf"
    assert "fixed" not in joints_of(urdf).values()
    whole = pin.buildModelFromUrdf(str(out / "urdf/talos.urdf"))
    arm = pin.buildModelFromUrdf(str(urdf))
    assert {f.name for f in arm.frames if f.type == pin.FrameType.FIXED_JOINT} == {"universe"}
    assert "gripper_left_base_link" not in {f.name for f in arm.frames}
    for jid in range(1, arm.njoints):
        theirs = whole.inertias[whole.getJointId(arm.names[jid])]
        ours = arm.inertias[jid]
        assert np.isclose(ours.mass, theirs.mass, rtol=0, atol=1e-12), arm.names[jid]
        assert np.allclose(ours.lever, theirs.lever, atol=1e-12), arm.names[jid]
        assert np.allclose(ours.inertia, theirs.inertia, atol=1e-12), arm.names[jid]


def test_abstract_model_keeps_the_independent_joints(tmp_path: Path, diags: Diags) -> None:
    """abstract_model on TALOS with the left gripper as a submechanism: the six mimic joints
    merge away, every other joint stays; mass, COM and centroidal inertia at q = 0 are the
    whole robot's. joint_limits ABSTRACT lists the same movable joints."""
    spec = write(tmp_path / "m.yml", HEAD + SUBMECHANISMS + """
  export_config:
    - {type: urdf}
    - {type: joint_limits, joints: ABSTRACT, file_name: abstract_limits.yml}
    - {type: submodel, name: abstract, abstract_model: true}
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    # The submechanisms (serial chains, made anew for the abstract model) are in each SMURF.
    assert (out / "submodels/abstract/smurf/abstract_submechanisms.yml").is_file()
    whole, abstract = out / "urdf/talos.urdf", out / "submodels/abstract/urdf/abstract.urdf"
    assert set(joints_of(whole)) - set(joints_of(abstract)) == set(GRIPPER[1:])
    (m1, c1, I1), (m2, c2, I2) = centroidal(whole), centroidal(abstract)
    assert np.isclose(m1, m2, rtol=0, atol=1e-12)
    assert np.allclose(c1, c2, atol=1e-12)
    assert np.allclose(I1, I2, atol=1e-10)
    movable = [n for n, t in joints_of(abstract).items() if t != "fixed"]
    listed = yaml.safe_load((out / "abstract_limits.yml").read_text())["limits"]["names"]
    assert sorted(listed) == sorted(movable)
    assert "gripper_left_joint" in listed and "gripper_left_fingertip_1_joint" not in listed
    # The abstract model (which inherits the entry) is its own abstract model.
    again = yaml.safe_load((out / "submodels/abstract/abstract_limits.yml").read_text())["limits"]["names"]
    assert again == listed


def test_abstract_model_without_submechanisms(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: submodel, name: abstract, abstract_model: true, export_config: [{type: urdf}]}
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    d = diags.take("W0522", Severity.WARNING)
    assert d.message == "submodel 'abstract': abstract_model needs submechanisms; the submodel has none, " \
                        "so it keeps its joints (as Phobos does)"
    assert "gripper_left_fingertip_1_joint" in joints_of(out / "submodels/abstract/urdf/abstract.urdf")


def test_remove_joints_by_pattern_and_the_limits_of_a_submodel(tmp_path: Path, diags: Diags) -> None:
    """remove_joints takes regular expressions; `joints: <submodel>` in the model's export_config
    lists that submodel's movable joints, in the model's folder; `filename` names the files."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: joint_limits, joints: left_arm, file_name: left_arm_limits.yml}
    - type: submodel
      name: left_arm
      filename: arm_only
      start: arm_left_1_link
      remove_joints: ["gripper_left_.*_joint", arm_left_7_joint]
      export_config: [{type: urdf}]
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    urdf = out / "submodels/left_arm/urdf/arm_only.urdf"
    kept = [n for n, t in joints_of(urdf).items() if t != "fixed"]
    expected = [f"arm_left_{i}_joint" for i in range(2, 7)] + ["gripper_left_joint"]
    assert sorted(kept) == sorted(expected)
    listed = yaml.safe_load((out / "left_arm_limits.yml").read_text())["limits"]["names"]
    assert listed == expected
    assert not (out / "submodels/left_arm/joint_limits.yml").exists()


def test_a_pattern_that_names_no_joint(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: submodel, name: arm, start: arm_left_1_link, remove_joints: [arm_left_8_joint]}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert diags.take_error("E0310").message == (
        "submodel 'arm': remove_joints 'arm_left_8_joint' names no joint of the submodel; did you mean "
        "'arm_left_7_joint'?")


def test_only_urdf_has_no_effect(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: submodel, name: arm, start: arm_left_1_link, only_urdf: true, export_config: [{type: pdf}]}
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    d = diags.take("W0523", Severity.WARNING)
    assert (d.message, d.hint) == ("'only_urdf' has no effect (Phobos stores it and never reads it)",
                                   "give the submodel an export_config with only urdf entries")
    assert (out / "submodels/arm/arm.pdf.gv").is_file()


def test_name_replacements_rename_the_submodel(tmp_path: Path, diags: Diags) -> None:
    """name_replacements (regular expressions) rename every name of the submodel, after the
    merges; the arm is the same arm under its new names."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: urdf}
    - type: submodel
      name: arm
      start: arm_left_1_link
      name_replacements: {"_left_": "_"}
      export_config: [{type: urdf}, {type: joint_limits}]
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    arm = pin.buildModelFromUrdf(str(out / "submodels/arm/urdf/arm.urdf"))
    assert list(arm.names)[1:7] == [f"arm_{i}_joint" for i in range(2, 8)]
    whole = pin.buildModelFromUrdf(str(out / "urdf/talos.urdf"))
    for i in range(2, 8):
        theirs = whole.inertias[whole.getJointId(f"arm_left_{i}_joint")]
        ours = arm.inertias[arm.getJointId(f"arm_{i}_joint")]
        assert np.isclose(ours.mass, theirs.mass, rtol=0, atol=1e-12)
    assert "arm_left" not in (out / "submodels/arm/joint_limits.yml").read_text()


def test_name_replacements_that_merge_two_names(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: submodel, name: arm, start: arm_left_6_link, name_replacements: {"_[67]_": "_"}}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert diags.take_error("E0302").message == \
        "name editing gives two links the name 'arm_left_link' ('arm_left_6_link' and 'arm_left_7_link')"


def test_move_joint_axis_to_intersection(tmp_path: Path, diags: Diags) -> None:
    """arm_left_1_joint's frame (0.232 m off torso_2_joint's axis) moves to where the axes of
    torso_2_joint and arm_left_1_joint meet; the link's body stays where it was (Pinocchio,
    q = 0)."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: urdf}
    - type: submodel
      name: arm
      start: torso_1_link
      stop: arm_left_2_link
      move_joint_axis_to_intersection: {arm_left_1_joint: [torso_2_joint, arm_left_1_joint]}
      export_config: [{type: urdf}]
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    arm = pin.buildModelFromUrdf(str(out / "submodels/arm/urdf/arm.urdf"))
    whole = pin.buildModelFromUrdf(str(out / "urdf/talos.urdf"))

    def placed(model: pin.Model) -> tuple[pin.Data, pin.SE3]:
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        return data, data.oMf[model.getFrameId("torso_1_link")]

    def axis_line(model: pin.Model, data: pin.Data, base: pin.SE3, joint: str) -> tuple[np.ndarray, ...]:
        i = model.getJointId(joint)
        X = base.actInv(data.oMi[i])
        return X.translation, X.rotation[:, "XYZ".index(model.joints[i].extract().shortname()[-1])]

    (da, ba), (dw, bw) = placed(arm), placed(whole)
    (p2, d2), (p1, _) = axis_line(arm, da, ba, "torso_2_joint"), axis_line(arm, da, ba, "arm_left_1_joint")
    (q2, e2) = axis_line(whole, dw, bw, "torso_2_joint")
    (q1, _) = axis_line(whole, dw, bw, "arm_left_1_joint")
    assert np.linalg.norm(np.cross(q1 - q2, e2)) > 0.2  # off the axis in the whole robot
    assert np.linalg.norm(np.cross(p1 - p2, d2)) < 1e-9  # on it in the submodel

    def com(model: pin.Model, data: pin.Data, base: pin.SE3) -> np.ndarray:
        i = model.getJointId("arm_left_1_joint")
        return base.actInv(data.oMi[i]).act(model.inertias[i].lever)

    assert np.allclose(com(arm, da, ba), com(whole, dw, bw), atol=1e-12)


def test_from_the_command_line(tmp_path: Path) -> None:
    """`mpc compile` on TALOS: the legs without fixed joints (sole links merged into the
    ankles), their joint limits, and the KCCD model of the legs; the one warning is W0520."""
    from tests.mpc_command import mpc

    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - type: submodel
      name: legs
      stop: ["leg_.*_6_link"]
      remove_fixed: true
      export_config: [{type: urdf}, {type: joint_limits}, {type: kccd}]
""")
    run = mpc("compile", spec, "-o", tmp_path / "out", "--format", "gcc")
    assert run.returncode == 0, run.stderr
    assert run.stderr == (
        f"{spec}:12:59: warning: urdf2kccd is not on PATH: wrote the hulls, kccd/legs.urdf and "
        "kccd/legs_kccd.yml; urdf2kccd would have made kccd/legs.cfg and legsKinematics.cfg from them, "
        "and kccdcoveriv each body's fitted volume [W0520]\n")
    legs = tmp_path / "out/submodels/legs"
    assert "fixed" not in joints_of(legs / "urdf/legs.urdf").values()
    names = yaml.safe_load((legs / "joint_limits.yml").read_text())["limits"]["names"]
    assert len(names) == 12
    assert len(list((legs / "meshes/iv").glob("*.stl"))) == 13  # base_link and twelve leg links
