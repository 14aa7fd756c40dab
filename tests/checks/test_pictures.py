"""The visual diff of `mpc test`: UR5 with its forearm moved by 5 cm against its release.
The protocol references pictures that exist; the moved link is coloured (reference palette:
orange in the new model, blue in the release), the unchanged links are grey."""

from __future__ import annotations

import io
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from mpc.checks.pictures import CHANGED_NEW, UNCHANGED
from tests.checks.helpers import compile_ok, definition, edited_urdf, floats, fmt, joint_el, run, write
from tests.conftest import ERD

UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"
RENDER = ("  export_config:\n    - type: urdf\n    - type: pdf\n    - type: render\n      size: [120, 90]\n"
          "      views: [iso, side]\n")


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


def picture(path: Path) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(path.read_bytes())).convert("RGB")).astype(int)


def orange(p: np.ndarray) -> int:
    """Pixels of the new model's colour for changed links (shaded: red well above blue)."""
    return int(np.sum((p[..., 0] - p[..., 2] > 60) & (p[..., 0] > p[..., 1])))


def blue(p: np.ndarray) -> int:
    return int(np.sum(p[..., 2] - p[..., 0] > 60))


def grey(p: np.ndarray) -> int:
    """Shaded grey robot pixels: not the white background, no hue."""
    spread = p.max(axis=2) - p.min(axis=2)
    return int(np.sum((spread < 12) & (p.max(axis=2) < 235)))


def tree_page(out: Path, tmp_path: Path) -> np.ndarray:
    """The protocol's kinematic tree PDF as a picture (poppler's pdftoppm)."""
    pdf = out / "test_pictures/kinematic_tree.pdf"
    subprocess.run(["pdftoppm", "-png", "-r", "40", "-singlefile", str(pdf), str(tmp_path / "tree")],
                   check=True)
    return picture(tmp_path / "tree.png")


def built_and_tested(tmp_path: Path, basefile: Path) -> Path:
    """Release: UR5 compiled into tmp_path/ref; then `basefile` tested against it. The output."""
    write(tmp_path / "ref.yml", definition(UR5, "ur5", "      - compare_amount_joints\n"))
    compile_ok(tmp_path / "ref.yml", tmp_path / "ref")
    text = definition(basefile, "ur5", "      - compare_link_transformations\n",
                      compare=f"      path: {tmp_path / 'ref'}\n")
    text = text.replace("  export_config:\n    - type: urdf\n      mesh_format: input_type\n", RENDER)
    write(tmp_path / "new.yml", text)
    protocol = run(tmp_path / "new.yml", tmp_path / "new", tmp_path / "work")
    protocol.write(tmp_path / "new")
    return tmp_path / "new"


def test_moved_forearm_is_coloured_in_the_pictures(tmp_path: Path) -> None:
    def move_forearm(root) -> None:
        origin = joint_el(root, "elbow_joint").find("origin")
        xyz = floats(origin.get("xyz"))
        origin.set("xyz", fmt([xyz[0], xyz[1], xyz[2] + 0.05]))

    moved = edited_urdf(UR5, tmp_path / "moved" / "ur5.urdf", move_forearm)
    out = built_and_tested(tmp_path, moved)
    markdown = (out / "test_protocol.md").read_text()
    assert "Changed links: `forearm_link` (moved by 0.05 m, turned by 0 rad)." in markdown
    referenced = [line.split("](")[1].split(")")[0] for line in markdown.split("![")[1:]]
    assert referenced == [f"test_pictures/{v}_{s}.png" for v in ("iso", "side")
                          for s in ("release", "new", "overlay")]
    for path in referenced:
        assert (out / path).is_file()  # relative to the protocol
    report = json.loads((out / "test_protocol.json").read_text())
    assert report["pictures"]["changed_links"] == {"forearm_link": "moved by 0.05 m, turned by 0 rad"}
    assert report["pictures"]["views"]["side"] == {s: f"test_pictures/side_{s}.png"
                                                   for s in ("release", "new", "overlay")}
    # the kinematic tree (the model has a pdf export), the moved link filled orange, the others grey
    assert report["pictures"]["kinematic_tree"] == "test_pictures/kinematic_tree.pdf"
    assert "[test_pictures/kinematic_tree.pdf](test_pictures/kinematic_tree.pdf)" in markdown
    assert (out / "test_pictures/kinematic_tree.pdf").read_bytes().startswith(b"%PDF")
    from mpc.backends.pdf import CHANGED as TREE_CHANGED
    from mpc.backends.pdf import UNCHANGED as TREE_GREY
    from mpc.backends.pdf import to_gv
    from mpc.backends.urdf_reader import read
    from mpc.core.diagnostics import Sink

    gv = to_gv(read(moved, Sink()), changed={"forearm_link"})
    assert gv.count(f'fillcolor="{TREE_CHANGED}"') == 1
    box = f'"link:forearm_link" [shape=box, label="forearm_link", style=filled, fillcolor="{TREE_CHANGED}"]'
    assert box in gv
    assert gv.count(f'fillcolor="{TREE_GREY}"') == gv.count("[shape=box") - 1
    assert orange(tree_page(out, tmp_path)) > 200  # one orange box on the page
    junit = (out / "test_protocol.junit.xml").read_text()
    assert '<property name="picture" value="test_pictures/iso_overlay.png"/>' in junit
    assert "[[ATTACHMENT|test_pictures/side_new.png]]" in junit

    new = picture(out / "test_pictures/side_new.png")
    release = picture(out / "test_pictures/side_release.png")
    assert new.shape == (90, 120, 3)
    # The forearm (a long tube of UR5's arm) is coloured, orange now and blue in the release …
    assert orange(new) > 150 and blue(new) == 0
    assert blue(release) > 150 and orange(release) == 0
    # … and it is the only coloured link: the other links (base, shoulder, upper arm, wrists)
    # are grey and cover more of the picture than the forearm; every robot pixel is orange or
    # grey but for the anti-aliased edges.
    assert grey(new) > orange(new)
    robot = int(np.sum(np.any(new < 245, axis=2)))
    assert orange(new) + grey(new) > 0.9 * robot
    overlay = picture(out / "test_pictures/side_overlay.png")
    assert np.any(overlay != new) and np.any(overlay != release)
    assert orange(overlay) < orange(new) and blue(overlay) < blue(release)  # at half strength
    assert UNCHANGED[0] == UNCHANGED[1] == UNCHANGED[2] and CHANGED_NEW[0] - CHANGED_NEW[2] > 0.5


def test_an_unchanged_model_is_all_grey(tmp_path: Path) -> None:
    out = built_and_tested(tmp_path, UR5)
    report = json.loads((out / "test_protocol.json").read_text())
    assert report["pictures"]["changed_links"] == {}
    assert "Changed links: none." in (out / "test_protocol.md").read_text()
    assert orange(tree_page(out, tmp_path)) == 0
    for view in ("iso", "side"):
        for side in ("release", "new", "overlay"):
            p = picture(out / f"test_pictures/{view}_{side}.png")
            assert orange(p) == 0 and blue(p) == 0 and grey(p) > 300, (view, side)
        assert (out / f"test_pictures/{view}_release.png").read_bytes() == \
            (out / f"test_pictures/{view}_new.png").read_bytes()


def test_without_egl_the_protocol_says_so_and_the_tests_still_count(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from mpc.core.diagnostics import Sink
    from tests.fixtures import arm

    urdf = arm(tmp_path)
    write(tmp_path / "ref.yml", definition(urdf, "arm", "      - compare_amount_joints\n"))
    compile_ok(tmp_path / "ref.yml", tmp_path / "ref")
    write(tmp_path / "new.yml", definition(urdf, "arm", "      - compare_amount_joints\n",
                                           compare=f"      path: {tmp_path / 'ref'}\n"))
    monkeypatch.setenv("PYOPENGL_PLATFORM", "glx")  # a desktop's setting: mpc draws through EGL only
    sink = Sink()
    protocol = run(tmp_path / "new.yml", tmp_path / "new", tmp_path / "work", sink)
    protocol.write(tmp_path / "new")
    assert not protocol.failed and protocol.pictures is not None
    [warning] = [d for d in sink.diagnostics if d.code == "W0720"]
    assert warning.message.startswith("the test protocol has no pictures: no EGL to draw with")
    markdown = (tmp_path / "new/test_protocol.md").read_text()
    assert "No pictures: no EGL to draw with (PYOPENGL_PLATFORM is 'glx'" in markdown
    assert not (tmp_path / "new/test_pictures").exists()
    assert json.loads((tmp_path / "new/test_protocol.json").read_text())["pictures"]["views"] == {}
