"""The render export on real robots (UR5, TALOS), checked by pixels: the size, the robot's
share of the frame, poses and geometries that differ, the same bytes from two builds; and its
bad values, each a diagnostic at its line and column."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from mpc.backends.render import draw_all
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.program import RenderExport
from tests.conftest import ERD, Diags, definition, write

UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"
TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"
UR5_POSES = """\
  poses:
    up:
      shoulder_lift_joint: -1.57
      elbow_joint: 1.0
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


def pixels(data: bytes) -> np.ndarray:
    image = Image.open(io.BytesIO(data))
    assert image.format == "PNG" and image.mode == "RGB"
    return np.asarray(image)


def robot_share(picture: np.ndarray, background: tuple[int, int, int] = (255, 255, 255)) -> float:
    """The fraction of pixels that are not the background colour."""
    return float(np.mean(np.any(np.abs(picture.astype(int) - background) > 8, axis=2)))


def build(tmp_path: Path, basefile: Path, entry: str, extra: str = "", out: str = "out"):
    text = definition(basefile, robotname="bot") + entry + extra
    path = write(tmp_path / "bot.yml", text)
    sink = Sink()
    result = compile_model(path, sink, Options(out=tmp_path / out))
    errors = [f"{d.span}: {d.code} {d.message}" for d in sink.diagnostics if d.severity.name == "ERROR"]
    assert result.out is not None, errors
    return result


def test_ur5_pictures_by_pose_and_view_framed_and_byte_stable(tmp_path: Path) -> None:
    entry = "    - type: render\n      size: [120, 90]\n"
    result = build(tmp_path, UR5, entry, UR5_POSES)
    folder = tmp_path / "out" / "render"
    names = sorted(p.name for p in folder.iterdir())
    assert names == [f"{pose}_{view}.png" for pose in ("up", "zero") for view in ("front", "iso", "side")]
    for name in names:
        picture = pixels((folder / name).read_bytes())
        assert picture.shape == (90, 120, 3)
        assert 0.04 < robot_share(picture) < 0.7, name  # framed: neither a speck nor cut off
        # the camera frames the whole robot: the border rows and columns are background
        assert robot_share(picture[[0, -1], :]) == 0 and robot_share(picture[:, [0, -1]]) == 0, name
    for view in ("front", "iso", "side"):
        assert (folder / f"up_{view}.png").read_bytes() != (folder / f"zero_{view}.png").read_bytes()
    again = build(tmp_path, UR5, entry, UR5_POSES, out="again")
    assert again.out is not None and result.out is not None
    for name in names:
        assert (tmp_path / "again" / "render" / name).read_bytes() == (folder / name).read_bytes()


def test_ur5_collision_pictures_differ_from_visual_ones(tmp_path: Path) -> None:
    result = build(tmp_path, UR5, "")
    assert result.robot is not None
    export = RenderExport(span=Span.of_file("x.yml"), views=("iso",), size=(96, 72))
    sink = Sink()
    drawn = {g: draw_all(result.robot, _with(export, geometry=g), sink)
             for g in ("visual", "collision", "both")}
    assert not sink.diagnostics
    visual, collision, both = (pixels(drawn[g]["zero_iso.png"]) for g in ("visual", "collision", "both"))
    assert np.mean(np.any(visual != collision, axis=2)) > 0.02
    # collisions are orange (translucent over the visuals with `both`); the visuals are grey
    def orange(p: np.ndarray, by: int) -> float:
        return float(np.mean((p[..., 0].astype(int) - p[..., 2]) > by))

    assert orange(visual, 20) == 0 and orange(collision, 60) > 0.04 and orange(both, 20) > 0.04


def _with(value, **changes):
    from dataclasses import replace

    return replace(value, **changes)


def test_talos_pictures_zero_pose_and_geometries(tmp_path: Path) -> None:
    entry = "    - type: render\n      size: [64, 96]\n      views: front\n      geometry: both\n"
    result = build(tmp_path, TALOS, entry)
    folder = tmp_path / "out" / "render"
    assert sorted(p.name for p in folder.iterdir()) == ["zero_front.png"]
    both = pixels((folder / "zero_front.png").read_bytes())
    assert both.shape == (96, 64, 3)
    assert 0.1 < robot_share(both) < 0.8
    assert result.robot is not None
    sink = Sink()
    bent = _with(result.robot, poses={"bent": {"leg_left_4_joint": 1.2, "arm_right_4_joint": -1.5}})
    export = RenderExport(span=Span.of_file("x.yml"), views=("front",), size=(64, 96), geometry="visual")
    visual = draw_all(bent, export, sink)
    # TALOS's arms cannot be at 0 within their limits (issue 29, point 20)
    assert visual is not None and [(d.code, d.message) for d in sink.diagnostics] == [(
        "W0590", "2 joints of robot 'bot' cannot be at 0 within their limits and are drawn at the limit "
        "nearest 0: 'arm_left_2_joint' at 0.00872665, 'arm_right_2_joint' at -0.00872665")]
    sink.diagnostics.clear()
    assert sorted(visual) == ["bent_front.png", "zero_front.png"]
    zero, bent_picture = pixels(visual["zero_front.png"]), pixels(visual["bent_front.png"])
    assert np.mean(np.any(zero != both, axis=2)) > 0.02  # collisions drawn over the visuals
    assert np.mean(np.any(zero != bent_picture, axis=2)) > 0.01
    assert draw_all(bent, export, sink) == visual  # the same bytes again


@pytest.mark.parametrize(("entry", "code", "where", "message"), [
    ("views: [iso, fronts]", "E0572", (13, 20),
     "render view 'fronts' is none of iso, front, side, back, top; did you mean 'front'?"),
    ("views: [iso, iso]", "E0572", (13, 20), "render view 'iso' is listed twice"),
    ("size: [10, 4]", "E0573", (13, 13),
     "size [10, 4] is not [width, height] in pixels, each from 16 to 4096"),
    ("background: pink", "E0574", (13, 19), "background 'pink' is no colour: write one of white, "
     "black, grey, gray or [r, g, b] with each from 0 to 1"),
    ("poses: [zero, sitting]", "E0575", (12, 7), "render pose 'sitting' is neither 'zero' nor a pose "
     "of robot 'bot'"),
])
def test_bad_render_values(tmp_path: Path, diags: Diags, entry: str, code: str,
                           where: tuple[int, int], message: str) -> None:
    path = write(tmp_path / "bot.yml", definition(UR5, robotname="bot")
                 + f"    - type: render\n      {entry}\n")
    result = compile_model(path, diags, Options(out=tmp_path / "out"))
    assert result.out is None and not (tmp_path / "out").exists()
    d = diags.take_error(code)
    assert d.message == message
    assert (d.span.line, d.span.col) == where


def test_no_egl_is_an_error_naming_what_to_install(tmp_path: Path, diags: Diags,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PYOPENGL_PLATFORM", "glx")  # what a desktop session without EGL has
    path = write(tmp_path / "bot.yml", definition(UR5, robotname="bot") + "    - type: render\n")
    assert compile_model(path, diags, Options(out=tmp_path / "out")).out is None
    d = diags.take_error("E0570")
    assert d.message.startswith("cannot draw robot 'bot' without a display: MuJoCo found no EGL")
    assert d.hint is not None and "apt-get install libegl1 libgl1-mesa-dri" in d.hint


def test_two_render_exports_in_one_folder(tmp_path: Path, diags: Diags) -> None:
    path = write(tmp_path / "bot.yml", definition(UR5, robotname="bot")
                 + "    - type: render\n    - type: render\n      views: top\n")
    assert compile_model(path, diags, Options(out=tmp_path / "out")).out is None
    d = diags.take_error("E0576")
    assert d.message == "two render exports would write render/"
    assert (d.span.line, d.span.col) == (13, 7) and d.notes[0][0].line == 12
