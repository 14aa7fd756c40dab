"""A build and its release → the Markdown of what changed, for the merge request that delivers
the build (`mpc deploy`, the pipeline's deploy stage): `mpc diff`'s changes and pictures.

deploy/ does not import checks/ (they are one floor): the caller hands deploy_model the
function `review_of` makes, and deploy calls it with the release's files (the merge request's
target branch) and a folder for the pictures, which it commits into `test_pictures/` and
links. The new model is the build's model file (checks/models.py `built_model_file`); the
release's is the file at the same place in the release, else the one `mpc test` would find.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.ir.program import Program, Tolerances

Review = Callable[[Path, Path], str]
PREFIX = "diff_"  # the pictures' names in test_pictures/, beside mpc test's
TITLE = "Changes against the release"


def review_of(program: Program, built: Path) -> Review:
    """The review of `built` (compiled from `program`): release folder, pictures folder → Markdown."""

    def review(release: Path, pictures: Path) -> str:
        return markdown_against(program, built, release, pictures)

    return review


def markdown_against(program: Program, built: Path, release: Path, pictures: Path) -> str:
    """The Markdown of the changes from `release` to `built` with the tolerances of the
    definition's tests; the pictures written into `pictures` (`diff_<view>_<side>.png`) and
    linked as `test_pictures/…`. A sentence saying why, when a model cannot be read."""
    from mpc.checks.diff_models import changed_links, diff
    from mpc.checks.diff_report import markdown
    from mpc.checks.models import built_model_file, model_in_folder, read_model
    from mpc.checks.pictures import SIDES, draw, render_export

    new_path = built_model_file(program, built)
    if new_path is None or not new_path.is_file():
        return f"## {TITLE}\n\nThe build has no URDF or SDF of the whole robot to compare.\n"
    old_path = release / new_path.relative_to(built)
    if not old_path.is_file():
        found = model_in_folder(release)
        if found is None:
            return f"## {TITLE}\n\nThe release holds no model file: this is the first.\n"
        old_path = found
    sink = Sink()
    old, new = read_model(old_path, sink), read_model(new_path, sink)
    if old is None or new is None:
        problem = next((f"{d.message}" for d in sink.diagnostics if d.severity.name == "ERROR"), "")
        return f"## {TITLE}\n\nThe release's model cannot be read: {problem}\n"
    tol = program.test.tolerances if program.test is not None else Tolerances()
    d = diff(old, new, tol)
    links: dict[str, list[str]] = {}
    if d.changed:
        drawn = draw(old, new, tol, render_export(program.exports), Sink(),
                     changed=changed_links(d, old, new))
        pictures.mkdir(parents=True, exist_ok=True)
        for view in drawn.views if drawn.drawn else ():
            for side in SIDES:
                name = f"{PREFIX}{view}_{side}.png"
                (pictures / name).write_bytes(drawn.files[f"{view}_{side}.png"])
                links.setdefault(view, []).append(f"test_pictures/{name}")
    return markdown(d, "release", "this build", tol, links, title=TITLE)
