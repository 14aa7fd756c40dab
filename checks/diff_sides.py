"""A side of `mpc diff` (what the command line names) → the robot to compare.

A side is a model file (read by its format, backends/formats.py), a built output folder (its
model found as `mpc test` finds a compare model's, checks/models.py), a definition (compiled
through the build cache, its output read as `mpc test` reads it: with the motors, sensors,
poses and submechanisms the URDF cannot hold), or any of these at a git revision:
`PATH@REV`. The revision's tree is written once per commit into the cache
(`$MPC_CACHE_DIR/diff/<commit>`), so a definition there keeps its build between runs.
"""

from __future__ import annotations

import tarfile
import tempfile
from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.robot import Robot

DEFINITION_SUFFIXES = (".yml", ".yaml", ".ir")


class BadSide(Exception):
    """The command line names no side that can exist (exit 2, as for any bad argument)."""


@record(frozen=False)
class Side:
    """robot: the model; path: the file it was read from; label: the side as given."""

    robot: Robot
    path: Path
    label: str


def split_revision(text: str) -> tuple[Path, str]:
    """`PATH@REV` → (PATH, REV); an existing path (even with `@` in its name) has no revision."""
    if Path(text).exists() or "@" not in text:
        return Path(text), ""
    path, _, rev = text.rpartition("@")
    if not path or not rev:
        raise BadSide(f"'{text}': expected PATH@REVISION")
    return Path(path), rev


def load_side(text: str, sink: Sink, work: Path) -> Side | None:
    """The side `text` names; None when it cannot be read (diagnostics in `sink`); BadSide
    when it names nothing. `work`: a folder for the builds, alive while the side is used."""
    path, rev = split_revision(text)
    if rev:
        path = at_revision(path, rev, sink)
        if path is None:
            return None
    elif not path.exists():
        raise BadSide(f"'{text}' does not exist")
    robot, model = _read(path, sink, work)
    return Side(robot, model, text) if robot is not None and model is not None else None


def _read(path: Path, sink: Sink, work: Path) -> tuple[Robot | None, Path | None]:
    from mpc.checks.models import MODEL_PATTERNS, model_in_folder, read_model

    if path.is_dir():
        found = model_in_folder(path)
        if found is None:
            sink.error(Span.of_file(str(path)), "E0740",
                       f"no model file ({', '.join(MODEL_PATTERNS)}) in folder '{path}'")
            return None, None
        path = found
    suffix = path.suffix.lower()
    if suffix in DEFINITION_SUFFIXES:
        return _compiled(path, sink, work)
    return read_model(path, sink), path


def _compiled(path: Path, sink: Sink, work: Path) -> tuple[Robot | None, Path | None]:
    """A definition, compiled into a fresh folder of `work` (the build cache makes a second
    compile of unchanged inputs a copy), its output read back as `mpc test` reads it; only
    the build's errors are reported."""
    from mpc.checks.models import load_built
    from mpc.compiler.driver import Options, compile_model

    out = Path(tempfile.mkdtemp(prefix="side-", dir=work)) / "build"
    built = Sink()  # the build's warnings (W0500 …) are not the diff's business; its errors are
    result = compile_model(path, built, Options(out=out))
    for d in built.diagnostics:
        if d.severity.name == "ERROR":
            sink.report(d)
    if result.program is None or result.robot is None or result.out is None:
        return None, None
    model, problem = load_built(result.program, result.out, result.robot)
    if model is None:
        sink.error(result.program.span, "E0740", f"cannot compare '{path}': {problem}")
        return None, None
    return model.robot, model.path


def at_revision(path: Path, rev: str, sink: Sink) -> Path | None:
    """`path` (in a git work tree) as it was at revision `rev`: its place in that commit's tree,
    written once into the cache. None, with E0741, when there is no such revision or file."""
    from mpc.core.cache import cache_dir
    from mpc.core.git_tree import write_tree
    from mpc.core.gitrun import GitFailed, git

    where = Span.of_file(str(path))
    folder = path.resolve().parent
    while not folder.is_dir():
        folder = folder.parent
    try:
        top = Path(git("rev-parse", "--show-toplevel", cwd=folder))
    except GitFailed as e:
        sink.error(where, "E0741", f"'{path}' is not in a git work tree: {e.message}")
        return None
    try:
        commit = git("rev-parse", "--verify", "--quiet", "--end-of-options", f"{rev}^{{commit}}", cwd=top)
    except GitFailed:
        sink.error(where, "E0741", f"the repository of '{path}' has no revision '{rev}'")
        return None
    try:
        inside = path.resolve().relative_to(top.resolve())
    except ValueError:  # a link out of the work tree
        sink.error(where, "E0741", f"'{path}' lies outside the git work tree '{top}'")
        return None
    tree = cache_dir("diff") / commit
    try:
        write_tree(top, commit, tree)
    except (GitFailed, OSError, tarfile.TarError) as e:
        sink.error(where, "E0741", f"cannot write revision '{rev}' of '{top}': "
                   f"{e.message if isinstance(e, GitFailed) else e}")
        return None
    found = tree / inside
    if not found.exists():
        sink.error(where, "E0741", f"'{inside.as_posix()}' does not exist at revision '{rev}' "
                   f"(commit {commit[:12]})")
        return None
    return found
