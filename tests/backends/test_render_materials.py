"""Pictures keep the colours of a DAE file with several materials (issue 29, point 20): a
two-material file the test writes (a red box and a blue box) is drawn red and blue by the
render export, through real MuJoCo EGL rendering, its two parts computed through the mesh
cache; a visual's own colour wins over the file's."""

from __future__ import annotations

import io
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Sink
from tests.conftest import write

RED, BLUE = "1 0 0", "0 0 1"


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


def _box(gid: str, cy: float, symbol: str) -> str:
    corners = [(x, cy + y, z) for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    numbers = " ".join(f"{c:g}" for p in corners for c in p)
    indices = " ".join(str(i) for f in faces for i in f)
    return (f'<geometry id="{gid}"><mesh><source id="{gid}-p"><float_array id="{gid}-a" count="24">'
            f'{numbers}</float_array><technique_common><accessor source="#{gid}-a" count="8" stride="3">'
            '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'
            f'</accessor></technique_common></source><vertices id="{gid}-v"><input semantic="POSITION" '
            f'source="#{gid}-p"/></vertices><triangles material="{symbol}" count="12"><input '
            f'semantic="VERTEX" source="#{gid}-v" offset="0"/><p>{indices}</p></triangles></mesh></geometry>')


def two_material_dae(path: Path, left: str = RED, right: str = BLUE) -> Path:
    """A COLLADA file of two boxes side by side along y, one per material (diffuse colours)."""
    def effect(name: str, rgb: str) -> str:
        return (f'<effect id="{name}-fx"><profile_COMMON><technique sid="common"><lambert><diffuse>'
                f'<color>{rgb} 1</color></diffuse></lambert></technique></profile_COMMON></effect>')

    def node(name: str, gid: str) -> str:
        return (f'<node id="{gid}-node"><instance_geometry url="#{gid}"><bind_material><technique_common>'
                f'<instance_material symbol="{name}-sym" target="#{name}"/></technique_common>'
                '</bind_material></instance_geometry></node>')

    return write(path, f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>
<library_effects>{effect("left", left)}{effect("right", right)}</library_effects>
<library_materials><material id="left"><instance_effect url="#left-fx"/></material>
<material id="right"><instance_effect url="#right-fx"/></material></library_materials>
<library_geometries>{_box("a", -0.15, "left-sym")}{_box("b", 0.15, "right-sym")}</library_geometries>
<library_visual_scenes><visual_scene id="s">{node("left", "a")}{node("right", "b")}</visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
""")


def model(tmp_path: Path, material: str = "") -> Path:
    two_material_dae(tmp_path / "meshes/boxes.dae")
    write(tmp_path / "boxes.urdf", f"""<robot name="boxes">
  {material}
  <link name="base"><visual><geometry><mesh filename="meshes/boxes.dae"/></geometry>
  {'<material name="green"/>' if material else ''}</visual></link>
</robot>
""")
    return write(tmp_path / "boxes.yml", textwrap.dedent("""\
        model:
          robotname: boxes
          modelname: boxes
          input_models: {base: {basefile: boxes.urdf}}
          assemble: {model: base}
          export_config:
            - type: render
              views: front
              size: [160, 120]
        """))


def picture(tmp_path: Path, definition: Path, out: str = "out") -> np.ndarray:
    sink = Sink()
    result = compile_model(definition, sink, Options(out=tmp_path / out))
    assert result.out is not None, [d.message for d in sink.diagnostics]
    image = Image.open(io.BytesIO((tmp_path / out / "render/zero_front.png").read_bytes()))
    return np.asarray(image.convert("RGB")).astype(int)


def share(rgb: np.ndarray, channel: int) -> float:
    """The fraction of pixels that are clearly of one primary colour (0 red, 1 green, 2 blue)."""
    others = [c for c in range(3) if c != channel]
    strong = (rgb[..., channel] > 100) & np.all(rgb[..., others] < 0.35 * rgb[..., [channel]], axis=-1)
    return float(np.mean(strong))


def test_each_material_of_a_dae_file_is_drawn_in_its_colour(tmp_path: Path) -> None:
    rgb = picture(tmp_path, model(tmp_path))
    assert share(rgb, 0) > 0.05 and share(rgb, 2) > 0.05  # red and blue boxes, each a good part
    left, right = rgb[:, :80], rgb[:, 80:]  # seen from the front (from +x), -y is on the left
    assert share(left, 0) > 0.1 and share(left, 2) == 0
    assert share(right, 2) > 0.1 and share(right, 0) == 0
    parts = sorted(p.name for p in (tmp_path / "cache/meshes").rglob("*.obj"))
    assert len(parts) == 2  # the two parts, through the mesh cache
    again = picture(tmp_path, model(tmp_path), out="again")  # from the cache: the same picture
    assert np.array_equal(again, rgb)


def test_a_visuals_own_colour_wins_over_the_files(tmp_path: Path) -> None:
    rgb = picture(tmp_path, model(tmp_path, '<material name="green"><color rgba="0 1 0 1"/></material>'))
    assert share(rgb, 1) > 0.1 and share(rgb, 0) == 0 and share(rgb, 2) == 0
