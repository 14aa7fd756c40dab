"""The two models a test run compares: the compiled one (from the output folder) and the
compare model (a git repository cloned with GitPython at a branch or commit, or a folder).

Both are read with mpc's own readers into robot values; a model that cannot be read is a
reason, not an exception, so the tests that need it fail with that reason.
"""

from __future__ import annotations

import hashlib
import shutil
from dataclasses import field, replace
from pathlib import Path
from typing import Any

from mpc.core.diagnostics import Sink
from mpc.core.files import resolved
from mpc.core.record import record
from mpc.ir.extras import Submechanism
from mpc.ir.program import CompareTarget, Program, SdfExport, UrdfExport
from mpc.ir.robot import Robot


@record(frozen=False)
class Model:
    """A model under test: its robot value and the file it was read from.

    folder: the folder whose files belong to the model (the output folder, the clone).
    commit: the compare repository's commit, when it came from git.
    """

    robot: Robot
    path: Path
    folder: Path
    commit: str = ""
    _dynamics: Any = field(default=None, repr=False)

    def dynamics(self) -> Any:
        """The Pinocchio model (checks/dynamics_model.py), built once; raises DynamicsError."""
        if self._dynamics is None:
            from mpc.checks.dynamics_model import build

            self._dynamics = build(self.robot)
        return self._dynamics


def read_model(path: Path, sink: Sink) -> Robot | None:
    """A model file (URDF, SDF, SMURF, MJCF) → a robot, read by the format its suffix names
    (backends/formats.py; a file of no known suffix as URDF); diagnostics go to `sink`.

    A SMURF (Phobos names one as compare model) is read with its annotations: cut joints,
    motors and submechanisms take part in the dynamics tests."""
    from mpc.backends.formats import reader_of

    read = reader_of(path).read
    assert read is not None  # reader_of answers only formats that read
    return read(path, sink, None)


MODEL_PATTERNS = ("urdf/*.urdf", "*.urdf", "sdf/*.sdf")  # a folder's model file, in this order


def model_in_folder(folder: Path) -> Path | None:
    """The model file of a folder that holds a model: its first URDF (in `urdf/`, then at the
    top), else its first SDF in `sdf/`."""
    return next((sorted(folder.glob(p))[0] for p in MODEL_PATTERNS if any(folder.glob(p))), None)


def read_submechanisms(path: Path) -> tuple[Submechanism, ...] | None:
    """The submechanisms of a HyRoDyn submechanisms file (`submechanisms: [{…}]`), or None
    when it cannot be read."""
    import yaml

    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError):
        return None
    entries = data.get("submechanisms") if isinstance(data, dict) else None
    if not isinstance(entries, list):
        return None
    return tuple(Submechanism(name=str(e.get("name", i)), definition=e)
                 for i, e in enumerate(entries) if isinstance(e, dict))


def built_model_file(program: Program, built: Path) -> Path | None:
    """The model file of the whole robot in an output folder: its first URDF export, else its
    first SDF export."""
    for kind in (UrdfExport, SdfExport):
        for export in program.exports:
            if isinstance(export, kind) and not export.submodel:
                suffix = "urdf" if kind is UrdfExport else "sdf"
                name = export.filename or program.robotname
                return built / suffix / f"{name}.{suffix}"
    return None


def load_built(program: Program, built: Path, robot: Robot | None) -> tuple[Model | None, str]:
    """The compiled model; `robot` (the program applied) lends it what URDF cannot hold:
    cut joints, motors and submechanisms. The model or None, and the reason."""
    path = built_model_file(program, built)
    if path is None:
        return None, "the definition exports no URDF or SDF of the whole robot"
    if not path.is_file():
        return None, f"'{path}' does not exist: compile the model first"
    sink = Sink()
    read = read_model(path, sink)
    if read is None:
        return None, f"cannot read '{path}': {_first_error(sink)}"
    if robot is not None:
        submechanisms = robot.submechanisms
        if not submechanisms and robot.submechanisms_file:  # a file used as it is
            folder = resolved(program.span.file).parent
            submechanisms = read_submechanisms(folder / robot.submechanisms_file) or ()
        read = replace(read, cut_joints=read.cut_joints or robot.cut_joints, motors=robot.motors,
                       submechanisms=submechanisms, poses=robot.poses, sensors=robot.sensors)
    return Model(robot=read, path=path, folder=built), ""


def load_compare(target: CompareTarget, workdir: Path, shown: str | None = None) -> tuple[Model | None, str]:
    """The compare model: cloned (git) or read from disk (path). The model or None, and why;
    `shown` names a folder in the reason (the protocol's name, checks/compare_name.py: not the
    runner's path), by default its path."""
    if target.git:
        folder, commit, problem = _clone(target, workdir)
        if folder is None:
            return None, problem
    else:
        assert target.path is not None
        folder, commit = target.path, ""
        if not folder.exists():
            return None, f"compare model path '{shown or folder}' does not exist"
    root = folder if folder.is_dir() else folder.parent  # where `…_in_repo` paths start
    path = folder / target.model_in_repo if target.model_in_repo else folder
    if path.is_dir():
        folder = path
        found = model_in_folder(path)
        if found is None:
            inside = shown and (f"{shown}/{target.model_in_repo}" if target.model_in_repo else shown)
            return None, (f"no model file ({', '.join(MODEL_PATTERNS)}) in '{inside or path}'; "
                          "name it with model_in_repo")
        path = found
    elif not path.is_file():
        return None, f"'{target.model_in_repo}' does not exist in the compare model" + (
            f" at commit {commit[:12]}" if commit else "")
    sink = Sink()
    robot = read_model(path, sink)
    if robot is None:
        return None, f"cannot read the compare model '{path.name}': {_first_error(sink)}"
    if target.submechanisms_in_repo:
        submechanisms = read_submechanisms(root / target.submechanisms_in_repo)
        if submechanisms is None:
            return None, f"cannot read submechanisms_in_repo '{target.submechanisms_in_repo}'"
        robot = replace(robot, submechanisms=submechanisms)
    return Model(robot=robot, path=path, folder=folder, commit=commit), ""


def _clone(target: CompareTarget, workdir: Path) -> tuple[Path | None, str, str]:
    """Clone the repository into `workdir` and check out the branch or commit; the work
    tree, the commit checked out, and the reason when it failed."""
    from mpc.core.gitrun import GitFailed, git, scrub, without_credentials

    key = hashlib.sha256(f"{without_credentials(target.git)}\0{target.branch}\0{target.commit}"
                         .encode()).hexdigest()[:12]
    folder = workdir / f"compare_model-{key}"
    if folder.exists():
        shutil.rmtree(folder)
    workdir.mkdir(parents=True, exist_ok=True)
    try:
        branch = ["--branch", target.branch] if target.branch else []
        git("clone", "--quiet", *branch, "--", target.git, str(folder))
        if target.commit:
            git("checkout", "--quiet", target.commit, cwd=folder)
        commit = git("rev-parse", "HEAD", cwd=folder)
    except (GitFailed, OSError) as e:
        shutil.rmtree(folder, ignore_errors=True)
        what = (f"commit '{target.commit}'" if target.commit else
                f"branch '{target.branch}'" if target.branch else "the default branch")
        why = e.message if isinstance(e, GitFailed) else str(e.strerror or e)
        return None, "", f"cannot get {what} of compare repository '{scrub(target.git)}': {why}"
    return folder, commit, ""


def _first_error(sink: Sink) -> str:
    return next((f"{d.span}: {d.message}" for d in sink.diagnostics if d.severity.name == "ERROR"),
                "unreadable")
