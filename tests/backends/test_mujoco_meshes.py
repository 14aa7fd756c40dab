"""The meshes of an MJCF export are files MuJoCo reads (backends/mujoco_meshes.py), checked by
MuJoCo: an ASCII STL or an OBJ of several objects, which it refuses or reads in part, is written
again as `<name>_mujoco`; a mesh it refuses whatever is done is an error naming the file and
what in it, and no MJCF is written. The other exports copy the same files as they are."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from mpc.cli.main import main
from tests.conftest import definition, write
from tests.fixtures import ARM_URDF, arm

TETRA = [(0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.0, 0.1, 0.0), (0.0, 0.0, 0.1)]
FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
TETRA_OBJ = "".join(f"v {x} {y} {z}\n" for x, y, z in TETRA) + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
MJCF = "    - type: mjcf\n      mesh_format: {fmt}\n"


def _stl(triangles: list[list[tuple[float, float, float]]]) -> bytes:
    data = bytearray(80) + struct.pack("<I", len(triangles))
    for triangle in triangles:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in triangle) + b"\0\0"
    return bytes(data)


def _ascii_stl() -> str:
    facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in
                     (TETRA[i] for i in face)) + "endloop\nendfacet\n" for face in FACES)
    return f"solid tetra\n{facets}endsolid tetra\n"


def _compile(folder: Path, mesh: str, data: str | bytes, exports: str,
             capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    arm(folder, ARM_URDF.replace("meshes/tetra.stl", f"meshes/{mesh}"))
    path = folder / "meshes" / mesh
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    spec = write(folder / "model.yml", definition("arm.urdf") + exports)
    code = main(["compile", str(spec), "-o", str(folder / "out")])
    return code, capsys.readouterr().err


def _mujoco_mesh(mjcf: Path) -> tuple[np.ndarray, int]:
    """The vertices and the number of triangles of the one mesh MuJoCo compiled from `mjcf`."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert model.nmesh == 1
    start, count = model.mesh_vertadr[0], model.mesh_vertnum[0]
    return model.mesh_vert[start:start + count], int(model.mesh_facenum[0])


def test_an_ascii_stl_is_written_as_binary_for_mujoco_and_copied_for_urdf(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = _compile(tmp_path, "tetra.stl", _ascii_stl(), MJCF.format(fmt="stl"), capsys)
    assert code == 0, err
    out = tmp_path / "out"
    assert (out / "meshes/stl/tetra.stl").read_bytes() == (tmp_path / "meshes/tetra.stl").read_bytes()
    assert 'filename="../meshes/stl/tetra.stl"' in (out / "urdf/robot.urdf").read_text()
    rewritten = (out / "meshes/stl/tetra_mujoco.stl").read_bytes()
    assert len(rewritten) == 84 + 50 * 4
    assert 'file="../meshes/stl/tetra_mujoco.stl"' in (out / "mjcf/robot.xml").read_text()
    # MuJoCo moves a mesh into its principal frame: the same tetrahedron written as a binary STL
    # by its modelling tool gives the same compiled mesh.
    vertices, triangles = _mujoco_mesh(out / "mjcf/robot.xml")
    assert _compile(tmp_path / "binary", "tetra.stl", _stl(_tetra_triangles()), MJCF.format(fmt="stl"),
                    capsys)[0] == 0
    expected, expected_triangles = _mujoco_mesh(tmp_path / "binary/out/mjcf/robot.xml")
    assert triangles == expected_triangles == 4
    assert np.array_equal(vertices, expected)


def test_an_obj_of_two_objects_is_written_as_one_for_mujoco(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """MuJoCo reads the first object of an OBJ only: the copy gave it half the mesh."""
    second = "".join(f"v {x + 1} {y} {z}\n" for x, y, z in TETRA) + "f 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n"
    text = f"o a\n{TETRA_OBJ}o b\n{second}"
    code, err = _compile(tmp_path, "two.obj", text, MJCF.format(fmt="obj"), capsys)
    assert code == 0, err
    out = tmp_path / "out"
    assert 'file="../meshes/obj/two_mujoco.obj"' in (out / "mjcf/robot.xml").read_text()
    assert (out / "meshes/obj/two.obj").read_text() == text  # the URDF export's copy
    vertices, triangles = _mujoco_mesh(out / "mjcf/robot.xml")
    assert triangles == 8 and len(vertices) == 8


def test_an_obj_mujoco_reads_whole_is_copied_as_it_is(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = "# a comment\n" + TETRA_OBJ.replace("f 1 3 2", "f -4 -2 -3")
    code, err = _compile(tmp_path, "tetra.obj", text, MJCF.format(fmt="obj"), capsys)
    assert code == 0, err
    assert (tmp_path / "out/meshes/obj/tetra.obj").read_text() == text
    assert _mujoco_mesh(tmp_path / "out/mjcf/robot.xml")[1] == 4


def test_an_obj_whose_faces_name_normals_in_part_is_written_again_for_mujoco(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """MuJoCo refuses it ("normal index out of bounds"); trimesh reads its triangles."""
    text = "vn 0 0 1\n" + TETRA_OBJ.replace("f 2 3 4", "f 2//1 3//1 4//1")
    code, err = _compile(tmp_path, "tetra.obj", text, MJCF.format(fmt="obj"), capsys)
    assert code == 0, err
    assert 'file="../meshes/obj/tetra_mujoco.obj"' in (tmp_path / "out/mjcf/robot.xml").read_text()
    assert _mujoco_mesh(tmp_path / "out/mjcf/robot.xml")[1] == 4


def _tetra_triangles() -> list[list[tuple[float, float, float]]]:
    return [[TETRA[i] for i in face] for face in FACES]


def _with(value: float) -> bytes:
    triangles = _tetra_triangles()
    triangles[1][2] = (0.0, value, 0.1)
    return _stl(triangles)


@pytest.mark.parametrize(("mesh", "data", "problem"), [
    ("nan.stl", _with(float("nan")), "triangle 2 has a coordinate that is not finite"),
    ("far.stl", _with(2.0**31), "triangle 2 has a coordinate beyond ±2^30, the largest MuJoCo reads"),
    ("few.stl", _stl([[(0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.0, 0.1, 0.0)]] * 4),
     "it has 3 vertices; MuJoCo reads a mesh of 4 or more"),
    ("few.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n",
     "it has 3 vertices; MuJoCo reads a mesh of 4 or more"),
    ("line.obj", "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0.3 0 0\nf 1 2 3\nf 2 3 4\n",
     "its triangles have no area (0 m² in all; MuJoCo refuses a mesh of less than 1e-15)"),
    ("word.obj", TETRA_OBJ.replace("f 1 2 4", "f 2 [[["), "a face corner '[[[' names no vertex (line 6)"),
    ("zero.obj", TETRA_OBJ.replace("f 1 2 4", "f 0 1 2"),
     "a face corner '0' names vertex 0 (an OBJ counts its vertices from 1) (line 6)"),
    ("beyond.obj", TETRA_OBJ.replace("f 1 2 4", "f 1 2 9"),
     "a face corner '9' names vertex 9 of the file's 4 (line 6)"),
    ("huge.obj", TETRA_OBJ.replace("f 1 2 4", "f 1 2 " + "9" * 5000),  # the fuzz run's: exit 3
     f"a face corner '{'9' * 37}...' names vertex {'9' * 37}... of the file's 4 (line 6)"),
    ("back.obj", TETRA_OBJ.replace("f 1 2 4", "f -1 -2 -5"),
     "a face corner '-5' counts back beyond the 4 vertices above it (line 6)"),
    ("corner.obj", TETRA_OBJ.replace("f 1 2 4", "f 1/1/1/1 2 4"),
     "a face corner '1/1/1/1' is not v, v/vt, v//vn or v/vt/vn (line 6)"),
    ("inf.obj", TETRA_OBJ.replace("v 0.1 0.0 0.0", "v 1e999 0.0 0.0"),
     "vertex 2 has a coordinate that is not finite ('1e999', line 2)"),
])
def test_a_mesh_mujoco_refuses_is_an_error_for_mjcf_and_copied_for_urdf(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], mesh: str, data: str | bytes,
        problem: str) -> None:
    fmt = mesh.rsplit(".", 1)[1]
    code, err = _compile(tmp_path / "mjcf", mesh, data, MJCF.format(fmt=fmt), capsys)
    assert code == 1
    assert (f"{tmp_path}/mjcf/arm.urdf:10:33: error[E0585]: mesh '{tmp_path}/mjcf/meshes/{mesh}' of a visual "
            f"of link 'base' cannot be copied into the build: {problem}\n") in err
    assert "  hint: export the mesh again from its modelling tool\n" in err
    assert not (tmp_path / "mjcf/out/mjcf").exists()
    code, err = _compile(tmp_path / "urdf", mesh, data, "", capsys)
    assert code == 0, err
    copied = tmp_path / f"urdf/out/meshes/{fmt}/{mesh}"
    assert copied.read_bytes() == (tmp_path / f"urdf/meshes/{mesh}").read_bytes()


def test_an_stl_of_more_triangles_than_mujoco_reads_is_an_error_copied_or_computed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    many = _tetra_triangles() * 50_001  # 200,004 triangles
    code, err = _compile(tmp_path / "copied", "many.stl", _stl(many), MJCF.format(fmt="stl"), capsys)
    assert code == 1
    assert (f"error[E0585]: mesh '{tmp_path}/copied/meshes/many.stl' of a visual of link 'base' cannot be "
            "copied into the build: it has 200,004 triangles; MuJoCo reads at most 200,000 from an STL "
            "file\n") in err
    assert ("  hint: reduce the mesh (`reduce_meshes`) or write OBJ meshes (`mesh_format: obj`), which have "
            "no such limit\n") in err
    obj = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\n" + "f 1 2 3\n" * 200_001
    # Computed for the MJCF export, or by the SDF export before it, into the same file.
    for folder, exports in (("computed", ""), ("shared", "    - type: sdf\n      mesh_format: stl\n")):
        code, err = _compile(tmp_path / folder, "many.obj", obj, exports + MJCF.format(fmt="stl"), capsys)
        assert code == 1
        assert (f"error[E0588]: mesh 'meshes/stl/many.stl' of a visual of link 'base', computed from "
                f"'{tmp_path}/{folder}/meshes/many.obj' for MuJoCo, is one it refuses: it has 200,001 "
                "triangles; MuJoCo reads at most 200,000 from an STL file\n") in err
        assert not (tmp_path / folder / "out/mjcf").exists()


def test_laikago_in_mujoco_has_every_triangle_of_its_meshes(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """example-robot-data's Laikago: its trunk.obj is 54 objects; MuJoCo read 5,368 of its 22,246
    triangles from the copy an MJCF export used to make."""
    import mujoco
    import trimesh

    from mpc.core.packages import PackageResolver

    erd = PackageResolver().find("example-robot-data")
    assert erd is not None
    robot = erd / "robots/laikago_description"
    spec = write(tmp_path / "model.yml", definition(robot / "urdf/laikago.urdf").replace(
        "    - type: urdf\n      mesh_format: input_type\n", MJCF.format(fmt="obj")))
    assert main(["compile", str(spec), "-o", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out/mjcf/robot.xml"))
    compiled = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_MESH, i): int(model.mesh_facenum[i])
                for i in range(model.nmesh)}
    assert set(compiled) == {"trunk_mujoco", "hip", "thigh", "thigh_mirror", "calf"}
    for name, triangles in compiled.items():
        source = robot / "meshes" / (name.removesuffix("_mujoco").removesuffix("_mirror") + ".obj")
        assert triangles == len(trimesh.load(source, force="mesh", process=False).faces), name
    assert compiled["trunk_mujoco"] == 22_246


FLAT = [[(0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.1, 0.1, 0.0)],
        [(0.0, 0.0, 0.0), (0.1, 0.1, 0.0), (0.0, 0.1, 0.0)]]
FLAT_OBJ = "v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nf 1 2 3\nf 1 3 4\n"


@pytest.mark.parametrize(("mesh", "data", "fmt", "code", "named"), [
    ("flat.stl", _stl(FLAT), "stl", "E0585",
     "mesh '{tmp}/meshes/flat.stl' of a collision of link 'upper' cannot be copied into the build"),
    ("flat.obj", FLAT_OBJ, "stl", "E0588",
     "mesh 'meshes/stl/flat.stl' of a collision of link 'upper', computed from '{tmp}/meshes/flat.obj' for "
     "MuJoCo, is one it refuses"),
])
def test_a_flat_collision_mesh_is_an_error_for_mjcf_and_a_flat_visual_is_not(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], mesh: str, data: str | bytes, fmt: str,
        code: str, named: str) -> None:
    """MuJoCo computes the convex hull of a collision mesh, and refuses a flat one ("coplanar
    vertices, cannot compute convex hull"); a visual's it does not compute."""
    urdf = ARM_URDF.replace('<box size="0.05 0.05 0.4"/>', f'<mesh filename="meshes/{mesh}"/>')
    arm(tmp_path, urdf)
    path = tmp_path / "meshes" / mesh
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    spec = write(tmp_path / "model.yml", definition("arm.urdf") + MJCF.format(fmt=fmt))
    assert main(["compile", str(spec), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert (f"error[{code}]: {named.format(tmp=tmp_path)}: its vertices lie in one plane, and MuJoCo "
            "computes the convex hull of a collision mesh\n") in err
    assert ("  hint: give the link a primitive collision instead (`collisions: {<link>: {shape: box}}`), "
            "as MuJoCo suggests\n") in err
    visual = ARM_URDF.replace("meshes/tetra.stl", f"meshes/{mesh}")
    arm(tmp_path / "visual", visual)
    (tmp_path / "visual/meshes" / mesh).write_bytes(path.read_bytes())
    spec = write(tmp_path / "visual/model.yml", definition("arm.urdf") + MJCF.format(fmt=fmt))
    assert main(["compile", str(spec), "-o", str(tmp_path / "visual/out")]) == 0, capsys.readouterr().err
    _mujoco_mesh(tmp_path / "visual/out/mjcf/robot.xml")  # MuJoCo compiles it


def _far_tetra(z: str) -> str:
    """The tetrahedron as OBJ with its top corner at height `z`, written as given."""
    return TETRA_OBJ.replace("v 0.0 0.0 0.1\n", f"v 0.0 0.0 {z}\n")


@pytest.mark.parametrize("z", ["1e20", "3.4e38", "0.1000001e308"])
def test_a_collision_mesh_with_a_coordinate_far_out_is_an_error_for_mjcf_and_a_visual_is_not(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], z: str) -> None:
    """MuJoCo's convex hull (qhull) of a collision mesh with a corner at 1e20 fails, and so does
    MuJoCo; at 1e307 the test for flatness overflowed (an exit 3, found by the fuzz run). A visual
    mesh MuJoCo reads as it is. The rule is the bound of its STL reader, ±2^30."""
    import mujoco

    def loads(collision: bool) -> bool:
        (tmp_path / "probe.obj").write_text(_far_tetra(z))
        contact = 'contype="1" conaffinity="1"' if collision else 'contype="0" conaffinity="0"'
        try:
            mujoco.MjModel.from_xml_string(
                f'<mujoco><compiler meshdir="{tmp_path}"/><asset><mesh file="probe.obj"/></asset>'
                f'<worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
                f'<geom type="mesh" mesh="probe" {contact} mass="0"/></body></worldbody></mujoco>')
        except ValueError:
            return False
        return True

    assert not loads(collision=True) and loads(collision=False)  # MuJoCo's own verdicts
    urdf = ARM_URDF.replace('<box size="0.05 0.05 0.4"/>', '<mesh filename="meshes/far.obj"/>')
    arm(tmp_path / "collision", urdf)
    (tmp_path / "collision/meshes/far.obj").write_text(_far_tetra(z))
    spec = write(tmp_path / "collision/model.yml", definition("arm.urdf") + MJCF.format(fmt="input_type"))
    assert main(["compile", str(spec), "-o", str(tmp_path / "collision/out")]) == 1
    assert (f"error[E0585]: mesh '{tmp_path}/collision/meshes/far.obj' of a collision of link 'upper' "
            "cannot be copied into the build: triangle 2 has a coordinate beyond ±2^30, where MuJoCo "
            "cannot compute the convex hull of a collision mesh\n") in capsys.readouterr().err
    code, err = _compile(tmp_path / "visual", "far.obj", _far_tetra(z), MJCF.format(fmt="input_type"), capsys)
    assert code == 0, err
    _mujoco_mesh(tmp_path / "visual/out/mjcf/robot.xml")


def test_a_render_draws_every_object_of_an_obj(tmp_path: Path) -> None:
    """A render loads the robot in MuJoCo too (backends/scene.py): the OBJ of two objects is
    written again for it, and MuJoCo has both."""
    from mpc.backends import urdf
    from mpc.backends.scene import Scene
    from mpc.core.diagnostics import Sink
    from mpc.core.span import Span

    second = "".join(f"v {x + 1} {y} {z}\n" for x, y, z in TETRA) + "f 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n"
    arm(tmp_path, ARM_URDF.replace("meshes/tetra.stl", "meshes/two.obj"))
    (tmp_path / "meshes/two.obj").write_text(f"o a\n{TETRA_OBJ}o b\n{second}")
    sink = Sink()
    robot = urdf.read(tmp_path / "arm.urdf", sink)
    assert robot is not None
    scene = Scene.build(robot, tmp_path / "work", sink, Span("model.yml", 1, 1))
    assert scene is not None, [d.message for d in sink.diagnostics]
    assert (tmp_path / "work/meshes/obj/two_mujoco.obj").is_file()
    assert [int(n) for n in scene.model.mesh_facenum] == [8]
