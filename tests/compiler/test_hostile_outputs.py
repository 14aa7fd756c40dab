"""What the fuzz campaign of issue 29 found (points 24 and 25), one test per class: inputs
that ended in exit 3 (a symbolic link loop, a mesh trimesh reads into arrays of the wrong
shape, an inertia whose principal axes overflow) and inputs that were accepted but gave
outputs their consumers refuse (numbers that are not finite, a namespaced attribute written
in lxml's `{uri}name`, a DAE that is not well-formed). Each is now a located error naming the
input responsible, or a sound output checked by its consumer (check_urdf, expat)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path
from xml.parsers import expat

import pytest

from mpc.cli.main import main
from tests.conftest import definition, write
from tests.fixtures import ARM_URDF, arm
from tests.mpc_command import mpc_process


def _mpc(capsys: pytest.CaptureFixture[str], *args: str | Path) -> tuple[int, str]:
    code = main([str(a) for a in args])
    return code, capsys.readouterr().err


def _model(folder: Path, urdf: str = ARM_URDF, exports: str = "") -> Path:
    arm(folder, urdf)
    return write(folder / "model.yml", definition("arm.urdf") + exports)


def _loop(path: Path) -> Path:
    path.unlink(missing_ok=True)
    path.symlink_to(path.name)
    return path


# -- 24. exit 3 ---------------------------------------------------------------------------------

def test_a_basefile_that_is_a_symlink_loop_is_an_error_at_the_basefile(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    _loop(tmp_path / "arm.urdf")
    for command in (("check", spec), ("compile", spec, "-o", tmp_path / "out")):
        code, err = _mpc(capsys, *command)
        assert code == 1
        assert (f"{spec}:6:17: error[E0601]: basefile '{tmp_path}/arm.urdf' of input model 'base' is a "
                "symbolic link that loops (it never reaches a file)") in err


def test_a_mesh_that_is_a_symlink_loop_is_an_error_naming_the_link(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    _loop(tmp_path / "meshes/tetra.stl")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{tmp_path}/arm.urdf:10:33: error[E0602]: mesh file '{tmp_path}/meshes/tetra.stl' of a visual "
            "of link 'base' is a symbolic link that loops (it never reaches a file)") in err


def test_a_pipeline_naming_a_definition_that_is_a_symlink_loop_reports_it_there(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _model(tmp_path)
    pipeline = write(tmp_path / "pipeline.yml",
                     "pipeline:\n  root: .\n  model_definitions: [model.yml, b.yml]\n")
    _loop(tmp_path / "b.yml")
    for command in (("check", pipeline), ("run", pipeline, "-o", tmp_path / "build")):
        code, err = _mpc(capsys, *command)
        assert code == 1
        assert (f"{pipeline}:3:34: error[E0601]: model definition 'b.yml' is a symbolic link that loops "
                "(it never reaches a file)") in err


def test_a_defaults_file_that_is_a_symlink_loop_is_an_error_at_defaults(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    spec.write_text("defaults: d.yml\n" + spec.read_text())
    _loop(tmp_path / "d.yml")
    code, err = _mpc(capsys, "check", spec)
    assert code == 1 and f"{spec}:1:11: error[E0601]" in err and "Traceback" not in err


# An OBJ whose vertex line holds one number: trimesh reads the vertices as an 8×1 array, and
# writing it as DAE failed in pycollada (DaeMalformedError) or as STL in trimesh (ValueError).
BROKEN_OBJ = "v 0 0 0\nv 0.1 0 0\nv 00\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.mark.parametrize("mesh_format", ["dae", "stl"])
def test_a_mesh_read_into_arrays_of_the_wrong_shape_is_an_error_naming_file_and_link(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], mesh_format: str) -> None:
    write(tmp_path / "meshes/broken.obj", BROKEN_OBJ)
    spec = _model(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/broken.obj"))
    spec.write_text(spec.read_text().replace("mesh_format: input_type", f"mesh_format: {mesh_format}"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{tmp_path}/arm.urdf:10:33: error[E0603]: cannot compute mesh 'meshes/{mesh_format}/broken."
            f"{mesh_format}' of a visual of link 'base' from '{tmp_path}/meshes/broken.obj': cannot read "
            f"mesh '{tmp_path}/meshes/broken.obj': its vertices are not points of 3 coordinates (an array "
            "of shape (4, 1))") in err


def test_a_mesh_with_a_coordinate_that_is_not_finite_is_an_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write(tmp_path / "meshes/nan.obj", BROKEN_OBJ.replace("v 00", "v 0 nan 0"))
    spec = _model(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/nan.obj"))
    spec.write_text(spec.read_text().replace("mesh_format: input_type", "mesh_format: dae"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert ("error[E0603]: cannot compute mesh 'meshes/dae/nan.dae' of a visual of link 'base'" in err
            and "a vertex has a coordinate that is not a finite number (nan or inf)" in err)


@pytest.mark.parametrize("inertia", [
    'ixx="1e308" ixy="1e308" ixz="0" iyy="1e308" iyz="0" izz="0.001"',
    'ixx="1.7e308" ixy="0" ixz="0" iyy="1.7e308" iyz="1.5e308" izz="0.001"',
])
def test_an_inertia_whose_principal_moments_overflow_is_refused_for_mjcf_at_its_link(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], inertia: str) -> None:
    urdf = ARM_URDF.replace('ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"', inertia)
    spec = _model(tmp_path, urdf, "    - type: mjcf\n      mesh_format: stl\n")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{tmp_path}/arm.urdf:20:3: error[E0586]: link 'upper' has an inertial MuJoCo cannot hold: its "
            "inertia is too large for its principal moments to be numbers (they overflow); no MJCF is "
            "written") in err
    assert not (tmp_path / "out/mjcf").exists()


MJCF, SDF = "    - type: mjcf\n      mesh_format: stl\n", "    - type: sdf\n      mesh_format: stl\n"


# `mpc check` leaves inertials to `correct_inertials` where it is set: compiling refuses one it
# cannot correct (not checked ahead).
@pytest.mark.parametrize(("command", "export"), [
    ("check", MJCF), ("check", SDF),
    ("compile", MJCF), ("compile", SDF), ("compile", SDF + "      correct_inertials: true\n")])
def test_an_inertia_whose_principal_moments_overflow_is_an_error_for_check_and_every_export(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], export: str, command: str) -> None:
    """What the fuzz found (an exit 3 of `mpc check`, LinAlgError): the inertial checks of
    `mpc check` and of the SDF export, and `correct_inertials`, meet the same tensor."""
    urdf = ARM_URDF.replace('ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"',
                            'ixx="1e308" ixy="1e308" ixz="0" iyy="1e308" iyz="0" izz="0.001"')
    spec = _model(tmp_path, urdf, export)
    code, err = _mpc(capsys, command, spec, *(("-o", tmp_path / "out") if command == "compile" else ()))
    assert code == 1, err
    assert f"{tmp_path}/arm.urdf:20:3: error[" in err
    assert "its inertia is too large for its principal moments to be numbers (they overflow)" in err
    assert "internal error" not in err and not (tmp_path / "out").exists()


# -- 25. accepted, but invalid outputs ------------------------------------------------------------

@pytest.mark.parametrize(("old", "new", "where"), [
    ('<origin xyz="0 0 0.1" rpy="0 0 0"/>', '<origin xyz="nan 0 0.1" rpy="0 0 0"/>',
     "14:18: error[E0480]: 'xyz' of <origin> in joint 'shoulder' must be 3 finite numbers, got 'nan 0 0.1'"),
    ('<mass value="1"/>', '<mass value="inf"/>',
     "23:20: error[E0480]: 'value' of <mass> in link 'upper' must be a finite number, got 'inf'"),
    ('effort="10"', 'effort="-inf"',
     "18:45: error[E0480]: 'effort' of <limit> in joint 'shoulder' must be a finite number, got '-inf'"),
    ('ixx="0.004"', 'ixx="1e999"',
     "24:21: error[E0480]: 'ixx' of <inertia> in link 'upper' must be a finite number, got '1e999'"),
    ("0.05 0.05 0.4", "0.05 NaN 0.4",
     "27:28: error[E0480]: 'size' of <box> in link 'upper' must be 3 finite numbers, got '0.05 NaN 0.4'"),
])
def test_a_urdf_number_that_is_not_finite_is_refused_where_it_is_read(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, where: str) -> None:
    spec = _model(tmp_path, ARM_URDF.replace(old, new, 1))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert f"{tmp_path}/arm.urdf:{where}" in err
    assert "hint: URDF readers (urdfdom, check_urdf) refuse nan and inf; write a finite number" in err
    assert not (tmp_path / "out").exists()


def test_an_sdf_number_that_is_not_finite_is_refused_where_it_is_read(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path, exports="    - type: sdf\n      mesh_format: stl\n")
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "built")[0] == 0
    sdf = tmp_path / "built/sdf/robot.sdf"
    text = sdf.read_text()
    sdf.write_text(text.replace("<mass>1</mass>", "<mass>inf</mass>", 1))
    line = next(n for n, ln in enumerate(sdf.read_text().splitlines(), 1) if "<mass>inf" in ln)
    model = write(tmp_path / "sdf.yml", definition(sdf))
    code, err = _mpc(capsys, "compile", model, "-o", tmp_path / "out")
    assert code == 1
    assert f"{sdf}:{line}:" in err and "error[E0480]: <mass> in link 'upper' must be 1 finite number, " \
                                     "got 'inf'" in err


def _well_formed(path: Path) -> None:
    expat.ParserCreate(namespace_separator=" ").Parse(path.read_bytes(), True)


@pytest.mark.parametrize(("robot", "written"), [
    ('<robot name="arm" xmlns:x="http://example.com/ns" x:attr="v">',
     '<robot name="robot" x:attr="v" xmlns:x="http://example.com/ns">'),
    ('<robot name="arm" xml:lang="en">', '<robot name="robot" xml:lang="en">'),
])
def test_a_namespaced_attribute_of_robot_is_written_with_its_prefix(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], robot: str, written: str) -> None:
    spec = _model(tmp_path, ARM_URDF.replace('<robot name="arm">', robot))
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "out")[0] == 0
    urdf = tmp_path / "out/urdf/robot.urdf"
    assert urdf.read_text().splitlines()[1] == written
    _well_formed(urdf)
    checked = subprocess.run(["check_urdf", str(urdf)], capture_output=True, text=True)
    assert checked.returncode == 0 and "Error" not in checked.stdout + checked.stderr


@pytest.mark.parametrize(("element", "written"), [
    ('<joint name="elbow" type="revolute">', '<joint name="elbow" type="revolute" y:k="1" xmlns:y="urn:y">'),
    ('<link name="lower">', '<link name="lower" y:k="1" xmlns:y="urn:y">'),
    ("<geometry><box", '<geometry y:k="1" xmlns:y="urn:y">'),
])
def test_a_namespace_declared_on_an_element_is_declared_where_its_attribute_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], element: str, written: str) -> None:
    tag, rest = element.split(">", 1)
    spec = _model(tmp_path, ARM_URDF.replace(element, f'{tag} xmlns:y="urn:y" y:k="1">{rest}'))
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "out")[0] == 0
    urdf = tmp_path / "out/urdf/robot.urdf"
    assert written in urdf.read_text()
    _well_formed(urdf)


NOT_WELL_FORMED_DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="1"/><up_axis>Z_UP</up_axis>&e;</asset>
</COLLADA>
"""


def test_a_dae_that_is_not_well_formed_is_not_copied_into_the_build(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write(tmp_path / "meshes/bad.dae", NOT_WELL_FORMED_DAE)
    spec = _model(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/bad.dae"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{tmp_path}/arm.urdf:10:33: error[E0585]: mesh '{tmp_path}/meshes/bad.dae' of a visual of link "
            "'base' cannot be copied into the build: it is not well-formed XML (Entity 'e' not defined, "
            "line 3, column 53)") in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("old", "new", "shown"), [
    ('<unit meter="1"/>', '<unit meter="nan"/>', "'nan', line 3"),
    ("<up_axis>Z_UP</up_axis>&e;", "<up_axis>Z_UP</up_axis>\n  <extra>1 -INF</extra>", "'-INF', line 4"),
    ("<up_axis>Z_UP</up_axis>&e;", "<up_axis>Z_UP</up_axis><extra>2.5e999</extra>", "'2.5e999', line 3"),
    ('<unit meter="1"/>', f'<unit meter="{"9" * 309}"/>', f"'{'9' * 309}', line 3"),
])
def test_a_dae_holding_a_number_that_is_not_finite_is_not_copied_into_the_build(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, shown: str) -> None:
    dae = NOT_WELL_FORMED_DAE.replace("&e;", "").replace(old.replace("&e;", ""), new)
    write(tmp_path / "meshes/nan.dae", dae)
    spec = _model(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/nan.dae"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"error[E0585]: mesh '{tmp_path}/meshes/nan.dae' of a visual of link 'base' cannot be copied "
            f"into the build: it holds a number that is not finite ({shown})") in err


def test_an_stl_whose_normals_do_not_parse_is_read_without_a_traceback(tmp_path: Path) -> None:
    """trimesh logs such a file with its traceback; mpc's users must never see one."""
    facet = "facet normal {n}\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
    write(tmp_path / "meshes/n.stl", "solid s\n" + facet.format(n="0 0 1") + facet.format(n="0 0.outer")
          + "endsolid s\n")
    spec = _model(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/n.stl"))
    spec.write_text(spec.read_text().replace("mesh_format: input_type", "mesh_format: obj"))
    # A process of its own: pytest's logging plugin would take the record in this one.
    done = mpc_process("compile", spec, "-o", tmp_path / "out",
                       env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")})
    assert "Traceback" not in done.stderr and "failed to extract" not in done.stderr
    assert done.returncode == 0


def test_a_library_warning_on_a_degenerate_mesh_reaches_no_user(tmp_path: Path) -> None:
    """The convex hull of a mesh with a coordinate of 3.4e38 (the fuzz run of 2026-11-27):
    trimesh's vertex merging casts it to an integer, and numpy printed its RuntimeWarning, with
    trimesh's source line, under mpc's messages."""
    import struct

    triangles = [((0, 0, 0), (0.1, 0, 0), (0, 0.1, 0)), ((0, 0, 0), (0.1, 0, 0), (0, 0, -3.4e38)),
                 ((0, 0, 0), (0, 0.1, 0), (0, 0, -3.4e38)), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, -3.4e38))]
    data = bytearray(80) + struct.pack("<I", len(triangles))
    for triangle in triangles:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in triangle) + b"\0\0"
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes/far.stl").write_bytes(bytes(data))
    urdf = ARM_URDF.replace('<box size="0.05 0.05 0.4"/>', '<mesh filename="meshes/far.stl"/>')
    spec = _model(tmp_path, urdf)
    spec.write_text(spec.read_text() + "  collisions:\n    $default:\n      shape: convex\n")
    done = mpc_process("compile", spec, "-o", tmp_path / "out",
                       env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")})
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/meshes/stl/far_hull.stl").is_file()
    assert "Warning" not in done.stderr and ".py:" not in done.stderr, done.stderr
    debug = mpc_process("compile", spec, "-o", tmp_path / "out2",
                        env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache2"), "MPC_DEBUG": "1"})
    assert "RuntimeWarning" in debug.stderr


def test_what_mujoco_warns_placing_a_scene_is_a_warning_not_a_log_in_the_working_folder(
        tmp_path: Path) -> None:
    """A link of 1.7e308 kg (the fuzz run of 2026-11-27): MuJoCo finds the joint-space inertia
    near singular as it loads the robot to place the scene's floor. It printed that on stdout
    and appended it to MUJOCO_LOG.TXT in the folder mpc was started from."""
    spec = _model(tmp_path / "model", ARM_URDF.replace('<mass value="0.5"/>', '<mass value="1.7e308"/>'),
                  "    - type: mjcf\n      scene: true\n")
    (tmp_path / "elsewhere").mkdir()
    done = mpc_process("compile", spec, "-o", tmp_path / "out", cwd=tmp_path / "elsewhere",
                       env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")})
    assert done.returncode == 0, done.stderr
    assert list((tmp_path / "elsewhere").iterdir()) == []
    assert "WARNING" not in done.stdout
    assert (f"{spec}:12:7: warning[W0506]: MuJoCo warns about the MJCF of robot 'robot' as it loads it to "
            "place the scene's floor: Inertia matrix is too close to singular, or the effective-metric "
            "solve failed to converge, at DOF 1. Check model. Time = 0.0000.\n") in done.stderr
    assert (tmp_path / "out/mjcf/robot_scene.xml").is_file()
