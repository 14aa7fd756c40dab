"""DAE meshes whose material or texture references are broken still give their triangles."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from mpc.core import collada
from mpc.core.diagnostics import Severity
from tests.conftest import Diags, compile_file, definition, write

# A tetrahedron in centimetres whose only material has an effect with a texture sampler that
# names a surface the file does not have (the image file was never shipped), as in the ANYmal
# foot of example-robot-data: pycollada drops the node's geometry when it binds that material.
TETRA_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_effects>
    <effect id="paint-effect">
      <profile_COMMON>
        <newparam sid="paint-sampler">
          <sampler2D><source>paint_png-surface</source></sampler2D>
        </newparam>
        <technique sid="common">
          <phong><diffuse><texture texture="paint-sampler" texcoord="UVMap"/></diffuse></phong>
        </technique>
      </profile_COMMON>
    </effect>
  </library_effects>
  <library_materials>
    <material id="paint-material" name="paint"><instance_effect url="#paint-effect"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="tetra-mesh" name="tetra">
      <mesh>
        <source id="tetra-positions">
          <float_array id="tetra-positions-array" count="12">0 0 0 10 0 0 0 10 0 0 0 10</float_array>
          <technique_common>
            <accessor source="#tetra-positions-array" count="4" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="tetra-vertices"><input semantic="POSITION" source="#tetra-positions"/></vertices>
        <triangles material="paint-material" count="4">
          <input semantic="VERTEX" source="#tetra-vertices" offset="0"/>
          <p>0 2 1 0 1 3 0 3 2 1 2 3</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="tetra" name="tetra" type="NODE">
        <instance_geometry url="#tetra-mesh" name="tetra">
          <bind_material><technique_common>
            <instance_material symbol="paint-material" target="#paint-material"/>
          </technique_common></bind_material>
        </instance_geometry>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="meshes/tetra.dae"/></geometry></visual>
  </link>
</robot>
"""

BROKEN = ("Effect not found: #paint-effect; Material #paint-material not found; "
          "Missing surface paint_png-surface")


def test_a_dae_with_a_missing_texture_gives_its_triangles_in_metres(tmp_path: Path) -> None:
    path = write(tmp_path / "tetra.dae", TETRA_DAE)
    mesh, broken = collada.read(path)
    assert len(mesh.faces) == 4
    assert mesh.bounds.ravel().tolist() == pytest.approx([0, 0, 0, 0.1, 0.1, 0.1])
    assert mesh.volume == pytest.approx(0.1**3 / 6)  # closed and wound outwards
    assert list(broken) == BROKEN.split("; ")


def test_an_intact_dae_is_read_as_trimesh_reads_it(tmp_path: Path) -> None:
    intact = TETRA_DAE.replace('<texture texture="paint-sampler" texcoord="UVMap"/>',
                               "<color>0.8 0.1 0.1 1</color>")
    intact = intact.replace("<sampler2D><source>paint_png-surface</source></sampler2D>",
                            "<float>1</float>")
    path = write(tmp_path / "tetra.dae", intact)
    mesh, broken = collada.read(path)
    assert broken == ()
    expected = trimesh.load(path, force="mesh", process=False)
    assert mesh.vertices.tolist() == (expected.vertices * 0.01).tolist()
    assert mesh.faces.tolist() == expected.faces.tolist()


def _arm(tmp_path: Path, dae: str) -> Path:
    write(tmp_path / "meshes/tetra.dae", dae)
    write(tmp_path / "arm.urdf", ARM)
    return write(tmp_path / "m.yml", definition(tmp_path / "arm.urdf", mesh_format="stl"))


def test_compiling_it_warns_in_every_build_cold_and_warm(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    spec = _arm(tmp_path, TETRA_DAE)
    for build in ("cold", "warm"):
        diags = Diags()
        out = compile_file(spec, tmp_path / build, diags).out
        assert out is not None
        w = diags.take("W0605", Severity.WARNING)
        assert w.message == (f"mesh '{tmp_path}/meshes/tetra.dae' of a visual of link 'base' has broken "
                             "references, ignored to read its triangles: " + BROKEN)
        assert (w.span.file, w.span.line) == (str(tmp_path / "arm.urdf"), 5)
        assert not diags.diagnostics
        stl = trimesh.load(out / "meshes/stl/tetra.stl")
        assert len(stl.faces) == 4 and stl.volume == pytest.approx(0.1**3 / 6)  # in metres
    stl = "meshes/stl/tetra.stl"
    assert (tmp_path / "cold" / stl).read_bytes() == (tmp_path / "warm" / stl).read_bytes()


def test_a_dae_without_triangles_is_still_E0603(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                 diags: Diags) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    empty = TETRA_DAE.replace('<triangles material="paint-material" count="4">',
                              '<triangles material="paint-material" count="0">').replace(
        "<p>0 2 1 0 1 3 0 3 2 1 2 3</p>", "<p></p>")
    spec = _arm(tmp_path, empty)
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0603")
    assert d.message == (f"cannot compute mesh 'meshes/stl/tetra.stl' of a visual of link 'base' from "
                         f"'{tmp_path}/meshes/tetra.dae': it has no triangles after reading")
