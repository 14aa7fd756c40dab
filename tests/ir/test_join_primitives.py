"""`join: union` of a link whose collisions are all primitives (issue 29, point 12): one closed
mesh named `<link>_joined`, their solid union, that every consumer loads."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import trimesh
import yaml
from lxml import etree

from tests.conftest import Diags, compile_file, write

# Two unit boxes overlapping by half: their union is 1.5 m³, from x = -0.5 to 1.
URDF = """\
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><origin xyz="0 0 0"/><geometry><box size="1 1 1"/></geometry></collision>
    <collision><origin xyz="0.5 0 0"/><geometry><box size="1 1 1"/></geometry></collision>
  </link>
</robot>
"""


def _definition(tmp_path: Path) -> Path:
    write(tmp_path / "r.urdf", URDF)
    return write(tmp_path / "m.yml", """
        model:
          robotname: r
          modelname: r_model
          input_models: {base: {basefile: r.urdf}}
          assemble: {model: base}
          collisions:
            base: {join: union}
          export_config:
            - {type: urdf}
            - {type: sdf}
            - {type: mjcf}
        """)


def test_a_union_of_primitives_is_one_closed_mesh(tmp_path: Path, diags: Diags) -> None:
    spec = _definition(tmp_path)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    collisions = etree.parse(str(out / "urdf/r.urdf")).getroot().findall("link/collision")
    assert [(c.get("name"), c.find("geometry/mesh").get("filename")) for c in collisions] == [
        ("base_joined", "../meshes/stl/base_joined.stl")]
    mesh = trimesh.load(out / "meshes/stl/base_joined.stl")
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert abs(mesh.volume - 1.5) < 1e-9
    np.testing.assert_allclose(mesh.bounds, [[-0.5, -0.5, -0.5], [1.0, 0.5, 0.5]], atol=1e-12)
    smurf = yaml.safe_load((out / "smurf/r_collisions.yml").read_text())["collisions"]
    assert [c["name"] for c in smurf] == ["base_joined"]
    assert subprocess.run(["check_urdf", str(out / "urdf/r.urdf")], capture_output=True).returncode == 0
    sdf = subprocess.run(["ign", "sdf", "-k", str(out / "sdf/r.sdf")], capture_output=True, text=True)
    assert "Valid." in sdf.stdout
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(out / "mjcf/r.xml"))
    assert model.nmesh == 1


def test_a_rebuild_gives_the_same_mesh(tmp_path: Path, diags: Diags) -> None:
    spec = _definition(tmp_path)
    first = compile_file(spec, tmp_path / "a", diags).out
    again = compile_file(spec, tmp_path / "b", diags).out
    assert first is not None and again is not None
    for rel in ("meshes/stl/base_joined.stl", "meshes/obj/base_joined.obj", "urdf/r.urdf"):
        assert (first / rel).read_bytes() == (again / rel).read_bytes(), rel
