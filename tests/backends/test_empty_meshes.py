"""A mesh without triangles (issue 29, point 11): warned about once per file, naming the file
and the links that use it; example-robot-data's 777 meshes are not warned about."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.backends.empty_meshes import has_no_triangles
from mpc.core.diagnostics import Severity
from tests.conftest import ERD, Diags, compile_file, definition, write

URDF = """\
<robot name="robot">
  <link name="a">
    <visual><geometry><mesh filename="empty.stl"/></geometry></visual>
    <collision><geometry><mesh filename="empty.stl"/></geometry></collision>
  </link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  <link name="b"><visual><geometry><mesh filename="empty.stl"/></geometry></visual></link>
</robot>
"""


def test_an_empty_mesh_is_warned_about_naming_the_file_and_its_links(tmp_path: Path, diags: Diags) -> None:
    (tmp_path / "empty.stl").write_bytes(b"\0" * 80 + (0).to_bytes(4, "little"))  # binary, 0 triangles
    spec = write(tmp_path / "m.yml", definition(write(tmp_path / "r.urdf", URDF)))
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    warning = diags.take("W0505", Severity.WARNING)
    assert warning.message == (f"mesh file '{tmp_path / 'empty.stl'}' has no triangles; it is used by the "
                               "visual of link 'a', the collision of link 'a', the visual of link 'b'")
    assert (Path(warning.span.file).name, warning.span.line) == ("r.urdf", 3)


@pytest.mark.parametrize(("name", "text", "empty"), [
    ("a.stl", b"solid x\nendsolid x\n", True),
    ("b.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
              b"endloop\nendfacet\nendsolid x\n", False),
    ("c.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", True),
    ("d.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", False),
    ("e.dae", b"<COLLADA><library_geometries><geometry><mesh/></geometry></library_geometries>"
              b"</COLLADA>", True),
    ("f.dae", b"<COLLADA><mesh><triangles count='1'><p>0 1 2</p></triangles></mesh></COLLADA>", False),
])
def test_each_format_is_told_empty_or_not(tmp_path: Path, name: str, text: bytes, empty: bool) -> None:
    (tmp_path / name).write_bytes(text)
    assert has_no_triangles(tmp_path / name) is empty


def test_no_mesh_of_example_robot_data_is_empty() -> None:
    meshes = [p for p in ERD.parent.rglob("*") if p.suffix.lower() in (".stl", ".obj", ".dae")]
    assert len(meshes) > 500
    assert [p for p in meshes if has_no_triangles(p)] == []
