"""Every example block of the language reference (model-definitions.md) parses.

The fixtures are the reference's examples with their lost indentation restored, each
inside a minimal model; they must validate with no diagnostic at all.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.compiler import inherit, schema
from mpc.core import yaml_source as source
from mpc.ir.robot import Robot
from tests.conftest import Diags

FIXTURES = sorted((Path(__file__).parents[1] / "fixtures" / "reference").glob("*.yml"))


@pytest.mark.parametrize("path", FIXTURES, ids=[p.stem for p in FIXTURES])
def test_reference_example_parses(path: Path, diags: Diags) -> None:
    doc = source.load(path, diags)
    assert doc is not None
    doc = inherit.resolve(doc, path, diags)
    assert doc is not None
    assert schema.validate(doc, diags) is not None


def test_every_section_of_the_reference_has_a_fixture() -> None:
    assert {p.stem for p in FIXTURES} == {
        "assemble", "name_editing", "cuts", "mirror", "export_config", "test", "deployment",
        "frames", "joints", "collisions", "poses", "materials", "sensors", "submechanisms",
        "submechanisms_file", "post_processing"}


EDITING = ["frames", "joints", "collisions", "poses", "materials", "sensors", "submechanisms",
           "submechanisms_file"]


def _compile_reference(name: str, tmp_path: Path) -> tuple[Robot, Diags]:
    from mpc.compiler.driver import Options, compile_model
    from tests.fixtures import reference_robot

    reference_robot(tmp_path / "base.urdf")
    spec = tmp_path / f"{name}.yml"
    spec.write_text((Path(__file__).parents[1] / "fixtures" / "reference" / f"{name}.yml").read_text())
    if name == "submechanisms_file":
        (tmp_path / "submechanisms.yml").write_text("submechanisms: []\n")
    sink = Diags()
    result = compile_model(spec, sink, Options(out=tmp_path / "out"))
    assert result.robot is not None and result.out is not None, sink.summary()
    sink.diagnostics = [d for d in sink.diagnostics if d.code != "W0500"]  # URDF leaves extras out
    return result.robot, sink


@pytest.mark.parametrize("name", EDITING)
def test_reference_example_compiles_with_its_effect(name: str, tmp_path: Path) -> None:
    robot, sink = _compile_reference(name, tmp_path)
    check = EFFECTS[name]
    check(robot)
    assert not sink.diagnostics, sink.summary()


def _frames(robot: Robot) -> None:
    joints = {j.child: j for j in robot.joints.values()}
    assert joints["right_arm_mount_link"].origin.xyz == pytest.approx((1.1, 0, 0))
    assert joints["control_frame"].parent == "left_arm_mount_link"
    assert joints["new_frame"].name == "new_frame_joint" and joints["new_frame"].parent == "root"
    assert robot.links["new_frame"].inertial.mass == 1.0
    assert robot.links["body_link_1"].annotations == {"noDataPackage": False, "reducedDataPackage": True}


def _joints(robot: Robot) -> None:
    import math

    j1 = robot.joints["body_joint_1"]
    assert (j1.limit.lower, j1.limit.upper, j1.limit.effort) == (-3.1415926, math.pi, 400.0)
    assert j1.limit.velocity == 2 * math.pi
    assert robot.motors["body_joint_1_motor"].settings == {"p": 20, "i": 0.001, "d": 0.1}
    assert "body_joint_2" not in robot.joints and "body_link_3" not in robot.links
    assert robot.joints["slider"].type == "fixed"
    cut = robot.cut_joints["body_loop_closure_joint"]
    assert (cut.parent, cut.child) == ("body_link_1", "body_link_2")
    assert robot.joints["left_arm_shoulder_joint1"].annotations["movement_depends_on"] == [
        {"joint_name": "left_exo_shoulder_1_joint", "multiplier": -1.0, "offset": 0.0}]
    # moved to where its axis meets the next shoulder axis: the two joints now share a point
    moved = robot.joints["left_arm_shoulder_joint1"].origin.xyz
    assert moved == pytest.approx((0.1, 0.0, 0.05))


def _collisions(robot: Robot) -> None:
    assert robot.links["left_arm_mount_link"].collisions == ()
    [box] = robot.links["right_arm_link"].collisions
    assert box.bitmask == 1 and box.annotations["ccfm"] == 0.002
    assert box.annotations["primitives"][0]["type"] == "box"
    assert "self_collision" in robot.annotations


def _poses(robot: Robot) -> None:
    # values outside [-1, 1] would be clamped; these are all inside
    assert robot.poses["init"]["LLKnee"] == 0.64 and len(robot.poses["init"]) == 13


def _materials(robot: Robot) -> None:
    assert robot.materials["shiny_blue_material"].rgba == (0.0, 0.0, 1.0, 1.0)


def _sensors(robot: Robot) -> None:
    assert robot.sensors["LLAnkle_ft"].link == "LLAnkle_FT"
    movable = {n for n, j in robot.joints.items() if j.type != "fixed"}
    assert set(robot.sensors["Joint_Position"].targets) == movable


def _submechanisms(robot: Robot) -> None:
    given, generated = robot.submechanisms[0], robot.submechanisms[1:]
    assert given.name == "rh5_torso" and given.definition["jointnames_active"] == ["Body_Act1", "Body_Act2"]
    assert generated and all(s.definition["auto_gen"] for s in generated)


def _submechanisms_file(robot: Robot) -> None:
    assert robot.submechanisms_file.endswith("submechanisms.yml")


EFFECTS = {"frames": _frames, "joints": _joints, "collisions": _collisions, "poses": _poses,
           "materials": _materials, "sensors": _sensors, "submechanisms": _submechanisms,
           "submechanisms_file": _submechanisms_file}
