"""Hostile names (issue 35.3): every name-bearing field, from a definition and from each input
format (URDF, SDF, SMURF), crossed with every export, writes nothing outside `-o`.

The arm carries one hostile name in one field; one compile writes every export at once (URDF
with both kinds of mesh paths, so a ROS package, SDF, SMURF, MJCF, joint limits, the PDF's
graph, kccd, render, a submodel). Whatever mpc says, exit 0 or 1, never 3, and the folder
around the output holds afterwards exactly what it held before.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mpc.cli.main import main
from tests.conftest import write
from tests.fixtures import ARM_URDF, arm

EXPORTS = """\
  export_config:
    - type: urdf
      mesh_format: input_type
      ros_pathes: true
      copy_with_other_pathes: true
    - type: sdf
      mesh_format: input_type
    - type: smurf
    - type: mjcf
    - type: joint_limits
    - type: pdf
    - type: kccd
    - type: render
      size: [32, 32]
      views: front
    - type: submodel
      name: part
"""

# The name becomes each of these, one per compile; `{abs}` is a path inside the test's folder;
# six `..` climb from a file of `meshes/iv/` or `config/` (once mpc made `collision_..`) into it.
# SAFE, the control, compiles (exit 0): what the hostile ones are refused for is their name.
SAFE = "ok.name"
HOSTILE = [SAFE, "../../x", "../../../../../../x", "{abs}", "a/b", ".."]

# A URDF whose link `upper`, joint `shoulder`, visual, collision and material carry names.
NAMED_URDF = ARM_URDF.replace(
    '<visual>\n      <geometry><mesh filename="meshes/tetra.stl"/></geometry>',
    '<visual name="base_visual">\n      <geometry><mesh filename="meshes/tetra.stl"/></geometry>\n'
    '      <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>').replace(
    "<collision>", '<collision name="upper_collision">')

# What each field of a URDF is called there, and how a definition sets one.
URDF_FIELDS = {"link": ('"upper"', "upper"), "joint": ('"shoulder"', "shoulder"),
               "visual": ('"base_visual"', None), "collision": ('"upper_collision"', None),
               "material": ('"grey"', None)}
DEFINITION_FIELDS = ("link", "joint", "visual", "collision", "submechanism", "pose", "sensor",
                     "motor", "material")
SMURF_FIELDS = ("pose", "sensor", "motor", "submechanism", "link")


def _urdf(field: str | None, name: str) -> str:
    """NAMED_URDF with `field`'s name replaced by `name` (XML-escaped as an attribute)."""
    if field is None:
        return NAMED_URDF
    quoted, _ = URDF_FIELDS[field]
    attr = json.dumps(name).replace("&", "&amp;").replace("<", "&lt;")
    return NAMED_URDF.replace(quoted, attr)


def _definition(basefile: str, section: str = "") -> str:
    return (f"model:\n  robotname: robot\n  modelname: robot_model\n  input_models:\n"
            f"    arm:\n      basefile: {basefile}\n  assemble:\n    model: arm\n{section}")


def _sections(field: str, name: str) -> str:
    """The sections of a definition that give `field` the name `name`."""
    n = json.dumps(name)
    prefixed = {"link": "link_prefix", "joint": "joint_prefix", "visual": "visual_prefix",
                "collision": "collision_prefix"}
    if field in prefixed:
        return f"    name_editing:\n      {prefixed[field]}: {n}\n"
    if field == "pose":
        return f"  poses:\n    {n}:\n      shoulder: 0.1\n"
    if field == "sensor":
        return f"  sensors:\n    - type: IMU\n      name: {n}\n      link: upper\n"
    if field == "motor":
        return f"  joints:\n    shoulder:\n      motor:\n        name: {n}\n"
    if field == "material":
        return f"  materials:\n    {n}:\n      diffuse: [0.3, 0.3, 0.3, 1]\n  visuals:\n    base:\n" \
               f"      material: {n}\n"
    assert field == "submechanism"
    return (f"  submechanisms:\n    - name: {n}\n      type: serial\n      contextual_name: arm\n"
            "      jointnames_spanningtree: [shoulder, elbow]\n"
            "      jointnames_independent: [shoulder, elbow]\n      jointnames_active: [shoulder, elbow]\n")


def _tree(folder: Path, out: Path) -> dict[str, bytes | None]:
    """Every path below `folder` but inside `out`, with its bytes (None: a folder)."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() and not p.is_symlink() else None)
            for p in folder.rglob("*") if out not in (p, *p.parents)}


def _compile(tmp_path: Path, spec: Path, capsys: pytest.CaptureFixture[str], name: str) -> None:
    out = tmp_path / "deep" / "er" / "out"
    before = _tree(tmp_path, out)
    code = main(["compile", str(spec), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0 if name == SAFE else code in (0, 1), err
    assert _tree(tmp_path, out) == before, err


def _hostile(tmp_path: Path, name: str) -> str:
    return name.format(abs=tmp_path / "abs")


def _sources(tmp_path: Path, text: str) -> Path:
    """The arm's files, its URDF `text`, in `tmp_path/src`; the folder."""
    folder = tmp_path / "deep" / "er" / "src"
    arm(folder, text)
    return folder


@pytest.mark.parametrize("name", HOSTILE)
@pytest.mark.parametrize("field", DEFINITION_FIELDS)
def test_a_hostile_name_from_the_definition_writes_nothing_outside_the_output(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], field: str, name: str) -> None:
    name = _hostile(tmp_path, name)
    src = _sources(tmp_path, NAMED_URDF)
    spec = write(src / "model.yml", _definition("arm.urdf", _sections(field, name)) + EXPORTS)
    _compile(tmp_path, spec, capsys, name)


@pytest.mark.parametrize("name", HOSTILE)
@pytest.mark.parametrize("field", URDF_FIELDS)
@pytest.mark.parametrize("fmt", ["urdf", "sdf"])
def test_a_hostile_name_from_an_input_model_writes_nothing_outside_the_output(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], fmt: str, field: str, name: str) -> None:
    name = _hostile(tmp_path, name)
    src = _sources(tmp_path, _urdf(field, name))
    basefile = "arm.urdf"
    if fmt == "sdf":  # the same model as SDF, written by mpc from the URDF
        made = src / "made"
        conv = write(src / "to_sdf.yml", _definition("arm.urdf") + "  export_config:\n    - type: sdf\n"
                     "      mesh_format: input_type\n")
        assert main(["compile", str(conv), "-o", str(made)]) == 0, capsys.readouterr().err
        basefile = "made/sdf/robot.sdf"
    spec = write(src / "model.yml", _definition(basefile) + EXPORTS)
    _compile(tmp_path, spec, capsys, name)


@pytest.mark.parametrize("name", HOSTILE)
@pytest.mark.parametrize("field", SMURF_FIELDS)
def test_a_hostile_name_from_an_input_smurf_writes_nothing_outside_the_output(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], field: str, name: str) -> None:
    """The SMURF is one mpc wrote with the name in it (its `_poses.yml`, `_sensors.yml`…)."""
    name = _hostile(tmp_path, name)
    src = _sources(tmp_path, _urdf("link", name) if field == "link" else NAMED_URDF)
    sections = "" if field == "link" else _sections(field, name)
    made = src / "made"
    first = write(src / "to_smurf.yml", _definition("arm.urdf", sections) + "  export_config:\n"
                  "    - type: urdf\n      mesh_format: input_type\n      link_in_smurf: true\n"
                  "    - type: smurf\n")
    assert main(["compile", str(first), "-o", str(made)]) == 0, capsys.readouterr().err
    written = (made / "smurf" / f"robot_{field}s.yml").read_text()
    assert f"name: {name}\n" in written or f"name: {json.dumps(name)}\n" in written \
        or f"name: '{name}'\n" in written, written  # the SMURF holds the name
    spec = write(src / "model.yml", _definition("made/smurf/robot.smurf") + EXPORTS)
    _compile(tmp_path, spec, capsys, name)


# -- mpc check says where the name comes from (E0540) -------------------------------------------

ROS = "  export_config:\n    - type: urdf\n      mesh_format: input_type\n      ros_pathes: true\n"
KCCD = "  export_config:\n    - type: kccd\n"
WHY = "it holds a '/' or '\\' (a file name, not a path)"


def _check(spec: Path, capsys: pytest.CaptureFixture[str]) -> str:
    code = main(["check", str(spec)])
    err = capsys.readouterr().err
    assert code == 1, err
    return err


def test_check_locates_a_pose_name_of_the_definition(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    src = _sources(tmp_path, NAMED_URDF)
    spec = write(src / "model.yml", _definition("arm.urdf", _sections("pose", "../../p")) + ROS)
    assert (f"{spec}:10:5: error[E0540]: the pose name '../../p' cannot be a file name, and the "
            f"export makes it config/init_positions_<pose>.yml of the ROS package: {WHY}"
            ) in _check(spec, capsys)


def test_check_locates_a_pose_name_of_an_input_smurf_in_its_poses_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = _sources(tmp_path, NAMED_URDF)
    first = write(src / "to_smurf.yml", _definition("arm.urdf", _sections("pose", "../../p")) +
                  "  export_config:\n    - type: urdf\n      mesh_format: input_type\n"
                  "      link_in_smurf: true\n    - type: smurf\n")
    assert main(["compile", str(first), "-o", str(src / "made")]) == 0, capsys.readouterr().err
    poses = src / "made" / "smurf" / "robot_poses.yml"
    line = next(i for i, t in enumerate(poses.read_text().splitlines(), 1) if "../../p" in t)
    spec = write(src / "model.yml", _definition("made/smurf/robot.smurf") + ROS)
    err = _check(spec, capsys)
    assert f"{poses}:{line}:" in err and "error[E0540]: the pose name '../../p'" in err


def test_check_locates_a_link_name_of_an_input_urdf(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    src = _sources(tmp_path, _urdf("link", "a/b"))
    spec = write(src / "model.yml", _definition("arm.urdf") + KCCD)
    assert (f"{src / 'arm.urdf'}:21:3: error[E0540]: the link name 'a/b' cannot be a file name, and "
            f"the export makes it meshes/iv/collision_<link>.stl of the kccd export: {WHY}"
            ) in _check(spec, capsys)


def test_check_locates_a_link_name_a_name_editing_prefix_makes(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = _sources(tmp_path, NAMED_URDF)
    spec = write(src / "model.yml", _definition("arm.urdf", _sections("link", "../")) + KCCD)
    err = _check(spec, capsys)
    assert f"{spec}:9:5: error[E0540]: the link name '../base' cannot be a file name" in err


def test_a_submodel_s_name_replacement_making_a_link_name_a_path_is_refused_at_its_export(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A name only a submodel has (its `name_replacements`), which `mpc check` does not see:
    compiling refuses it at the export that would make it a file name."""
    src = _sources(tmp_path, NAMED_URDF)
    spec = write(src / "model.yml", _definition("arm.urdf") + (
        "  export_config:\n    - type: submodel\n      name: part\n      name_replacements:\n"
        "        upper: ../../../../../../../x\n      export_config:\n        - type: kccd\n"))
    out = tmp_path / "deep" / "er" / "out"
    before = _tree(tmp_path, out)
    assert main(["compile", str(spec), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert (f"{spec}:15:11: error[E0540]: the link name '../../../../../../../x' cannot be a file "
            "name: it holds a '/' or '\\' (a file name, not a path); nothing is written") in err
    assert _tree(tmp_path, out) == before and not out.exists()
