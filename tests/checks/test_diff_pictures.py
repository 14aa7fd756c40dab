"""`mpc diff --pictures DIR`: the old, new and overlay renders of `mpc test`'s visual diff, the
changed links coloured (blue in the old model, orange in the new), a renamed link in both
under its own name; the Markdown shows them."""

from __future__ import annotations

from pathlib import Path

from tests.checks.test_diff import _cache, arm  # noqa: F401  (_cache: the cache in tmp_path)
from tests.checks.test_pictures import blue, grey, orange, picture
from tests.mpc_command import mpc


def test_the_moved_renamed_link_is_coloured_on_both_sides(tmp_path: Path) -> None:
    arm(tmp_path / "old")
    arm(tmp_path / "new", lower="forearm", elbow="0.35")
    run = mpc("diff", "old/arm.urdf", "new/arm.urdf", "--pictures", "pics", "--format", "markdown",
              cwd=tmp_path)
    assert run.returncode == 1, run.stderr
    assert "| iso | ![iso old](pics/iso_release.png) | ![iso new](pics/iso_new.png) | " \
           "![iso overlay](pics/iso_overlay.png) |\n" in run.stdout
    assert sorted(p.name for p in (tmp_path / "pics").iterdir()) == sorted(
        f"{view}_{side}.png" for view in ("iso", "front", "side") for side in ("release", "new", "overlay"))
    release, new = picture(tmp_path / "pics/iso_release.png"), picture(tmp_path / "pics/iso_new.png")
    assert blue(release) > 150 and orange(release) == 0  # 'lower' in the old model
    assert orange(new) > 150 and blue(new) == 0  # 'forearm' in the new one
    assert grey(new) > 150 and grey(release) > 150  # the base and the upper arm did not change


def test_an_unchanged_model_is_all_grey(tmp_path: Path) -> None:
    arm(tmp_path / "old")
    arm(tmp_path / "new")
    run = mpc("diff", "old/arm.urdf", "new/arm.urdf", "--pictures", "pics", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    for p in (tmp_path / "pics").iterdir():
        assert orange(picture(p)) == 0 and blue(picture(p)) == 0 and grey(picture(p)) > 150, p.name
