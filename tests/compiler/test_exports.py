"""Several exports of one model: each writes its own file, none overwrites another."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from tests.conftest import Diags, compile_file, write
from tests.fixtures import arm

HEAD = """
model:
  robotname: arm
  modelname: arm-model
  input_models: {arm: {basefile: arm.urdf}}
  assemble: {model: arm}
  export_config:
"""


def test_filename_suffix_keeps_two_urdf_exports_apart(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: urdf, mesh_format: stl}
    - {type: urdf, mesh_format: obj, filename_suffix: _obj}
    - {type: urdf, mesh_format: stl, filename: tool}
""")
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    assert sorted(p.name for p in (out / "urdf").iterdir()) == ["arm.urdf", "arm_obj.urdf", "tool.urdf"]
    mesh = etree.parse(str(out / "urdf/arm_obj.urdf")).getroot().find(".//mesh").get("filename")
    assert mesh == "../meshes/obj/tetra.obj" and (out / "meshes/obj/tetra.obj").is_file()


def test_two_exports_of_one_file_are_refused(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: urdf, mesh_format: stl}
    - {type: urdf, mesh_format: obj}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0503")
    assert d.message == ("two urdf exports would write urdf/arm (Phobos silently let the last one win); "
                         "give one a filename_suffix")
    assert (d.span.line, d.span.col, d.notes[0][0].line) == (9, 7, 8)
