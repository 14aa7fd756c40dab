"""Compile one model definition: YAML on disk → model files.

`compile_model` reads as a list of named phases; each stops the build when it
reported an error. The program and the robot come from the front end and the ops
(compiler/front_end.py), or from the build cache when nothing they depend on changed
(compiler/build_cache.py). Outputs are built in a temporary folder beside the output and
renamed into place only when everything succeeded, so a failed build leaves the
previous outputs untouched.
"""

from __future__ import annotations

import contextlib
import functools
import glob
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.compiler.options import Options
from mpc.core.diagnostics import Severity, Sink
from mpc.core.files import NotAFileName, OutsideOutput, confined, describe, resolved
from mpc.core.profile import stage
from mpc.core.span import Span

if TYPE_CHECKING:  # a build that writes its kept outputs reads no model (compiler/build_cache.py)
    from mpc.compiler.build_cache import KeptBuild
    from mpc.compiler.inputs import InputLoader
    from mpc.ir.program import Export, Program
    from mpc.ir.robot import Robot


class Result:
    """What a compilation produced: the program, the robot and the output folder. A build that
    wrote its kept outputs (compiler/build_cache.py) reads its program and robot when asked."""

    def __init__(self, program: Program | None = None, robot: Robot | None = None, out: Path | None = None,
                 model: Callable[[], tuple[Program | None, Robot | None]] | None = None) -> None:
        self._program, self._robot, self.out, self._model = program, robot, out, model

    def _load(self) -> None:
        if self._model is not None:
            self._program, self._robot = self._model()
            self._model = None

    @property
    def program(self) -> Program | None:
        self._load()
        return self._program

    @property
    def robot(self) -> Robot | None:
        self._load()
        return self._robot

    def __repr__(self) -> str:
        return f"Result(out={self.out!r})"


def emit(program: Program, robot: Robot, out: Path, sink: Sink, target: Path | None = None) -> bool:
    """Write every export into a fresh folder next to `out`, then swap it into place.

    An OSError (a read-only or full disk, a file where a folder must be, a name too long)
    is E0660 naming the path and what was being done; a name that would lead out of the
    output folder is E0653. Either way the previous output stays as it was.
    """
    return into_place(out, sink, program.span,
                      lambda staging: _emit_exports(program, robot, staging, out, sink, target), target)


def into_place(out: Path, sink: Sink, span: Span, fill: Callable[[Path], bool],
               target: Path | None = None) -> bool:
    """Fill a staging folder next to `out` (`fill` says whether it succeeded), then swap it into
    place; OSError and OutsideOutput raised while filling become E0660 and E0653 at `span`.
    A file of the staging folder is named where it was to be: in `target` (where `mpc run`
    moves the output), else in `out`."""
    step = "make the output's folder"
    staging: Path | None = None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_staging(out)
        step = "make a staging folder"
        staging = Path(tempfile.mkdtemp(prefix=_staging_prefix(out), suffix=".mpc-tmp", dir=out.parent))
        step = "write the output"
        if not fill(staging):
            return False
        step = "move the build into place"
        left = replace_folder(staging, out)
        if left is not None:
            sink.warning(span, "W0625", left)
        return True
    except OSError as e:
        if staging is not None and isinstance(e.filename, str) and e.filename.startswith(f"{staging}/"):
            e.filename = str(target or out) + e.filename[len(str(staging)):]
        sink.error(span, "E0660", f"{describe(e, step)}; the previous output is unchanged")
        return False
    except OutsideOutput as e:
        sink.error(span, "E0653", f"{e}; nothing is written there")
        return False
    finally:
        if staging is not None and staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _staging_prefix(out: Path) -> str:
    """`.<out>.<pid>.`: a later build removes the folders of builds that no longer run."""
    return f".{out.name[:100]}.{os.getpid()}."


def remove_stale_staging(out: Path) -> None:
    """Remove the staging (`.mpc-tmp`) and old-output (`.mpc-old-<pid>`) folders that killed
    builds of `out` left beside it; those of builds still running stay."""
    stem = f".{out.name[:100]}."
    for folder in out.parent.glob(f"{glob.escape(stem)}*"):
        rest = folder.name[len(stem):]
        if folder.name.endswith(".mpc-tmp"):
            pid = rest.split(".", 1)[0]
        elif rest.startswith("mpc-old-"):
            pid = folder.name.rsplit("-", 1)[-1]
        else:
            continue
        if not pid.isdigit() or not _running(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's process
    return True


def _emit_exports(program: Program, robot: Robot, staging: Path, out: Path, sink: Sink,
                  target: Path | None) -> bool:
    """Write every export into `staging`; whether all succeeded."""
    from mpc.backends.formats import write
    from mpc.ir.program import CommandExport, JointLimitsExport, RobotExport, SubmodelExport

    submodels: dict[str, Robot | None] = {}
    for export in program.exports:
        if isinstance(export, SubmodelExport):
            from mpc.ir.submodel import cut

            submodels[export.name] = part = cut(robot, export, sink)
            if part is not None and export.add_floating_base:
                submodels[export.name] = _floating(part, export, sink)
            continue
        if isinstance(export, CommandExport):
            from mpc.backends.commands import run

            if sink.has_errors() or not run(export, staging, target or out, sink):
                break  # the files a command would see are incomplete, or it failed
            continue
        model, folder = robot, staging
        if isinstance(export, RobotExport):
            if export.submodel:
                model = submodels[export.submodel]
                folder = confined(staging, "submodels", export.submodel)
            if isinstance(export, JointLimitsExport) and export.joints_of:
                model = submodels[export.joints_of]  # its joints, written where the entry is
            if model is not None and export.add_floating_base:
                model = _floating(model, export, sink)
            if model is not None and export.correct_inertials:
                model = _physical(model, export, sink)
            if model is None:
                continue
        folder.mkdir(parents=True, exist_ok=True)
        with stage(export.type):
            try:
                write(model, export, folder, sink)
            except NotAFileName as e:  # a name check_file_names could not see (a submodel's)
                sink.error(export.span, "E0540", f"{e}; nothing is written")
    return not sink.has_errors()


def _floating(robot: Robot, export: Export, sink: Sink) -> Robot | None:
    """`robot` with a floating base (ir/floating.py), or None with E0505."""
    from mpc.ir.floating import FLOATING_HINT, clash, with_floating_base

    floating = with_floating_base(robot)
    if floating is None and export.type != "smurf":  # a SMURF's flag is its model's, which said it
        sink.error(export.span, "E0505", clash(robot.links, robot.joints) or "", hint=FLOATING_HINT)
    return floating


def _physical(robot: Robot, export: Export, sink: Sink) -> Robot:
    """`robot` with its non-physical inertials made physical (ir/physical.py); W0530 names them.
    SDFormat and MuJoCo forgive no rounding: for their exports the correction is exact."""
    from mpc.backends.formats import FORMATS
    from mpc.ir.physical import correct_inertials

    robot, changed = correct_inertials(robot, exact=FORMATS[export.type].exact_inertials)
    if changed:
        more = f" and {len(changed) - 8} more" if len(changed) > 8 else ""
        shown = ", ".join(f"'{n}'" for n in changed[:8]) + more
        sink.warning(export.span, "W0530", f"correct_inertials made the inertials of {len(changed)} "
                     f"link{'s' if len(changed) > 1 else ''} physical: {shown}")
    return robot


def replace_folder(new: Path, out: Path) -> str | None:
    """Put `new` where `out` is; the old `out` disappears only after `new` is in place.

    The new output is in place either way; what cannot be removed of the old one (a folder
    made immutable, `chattr +i`, or read-only by another user) stays as `.<out>.mpc-old-<pid>`
    beside it, and the return value says so, naming it and why (W0625): None when all went."""
    if not out.exists():
        os.replace(new, out)
        return None
    old = out.with_name(f".{out.name[:100]}.mpc-old-{os.getpid()}")
    os.replace(out, old)
    try:
        os.replace(new, out)
    except OSError:
        os.replace(old, out)
        raise
    failed: list[tuple[str, BaseException]] = []  # (the path rmtree could not remove, why)
    shutil.rmtree(old, onerror=lambda _f, path, info: failed.append((path, info[1])))
    if not old.exists():
        return None
    path, error = failed[0] if failed else (str(old), None)
    reason = getattr(error, "strerror", None) or "it is still there"
    why = f"cannot remove '{path}': {reason}"
    return (f"the previous output, moved aside to '{old}', could not be removed ({why}); the new "
            "output is in place: remove the old one by hand (lsattr shows an immutable 'i' flag)")


def compile_model(path: Path, sink: Sink, options: Options) -> Result:
    """Compile the definition at `path`; diagnostics go to `sink`."""
    from mpc.backends import mesh_worker
    from mpc.compiler.build_cache import KeptBuild
    from mpc.core import meanwhile

    if _first_build(path, options):
        mesh_worker.start()  # imports numpy while the build looks for its kept build and reads its definition
    try:  # a mesh worker the build starts (backends/mesh_worker.py) ends with its mesh stages
        with stage("lower"):
            kept = KeptBuild.open(path, options)                   # the last build, if it still holds
        if kept is not None:
            kept.report_refused(sink, Span.of_file(str(path)))     # an entry not read (W0650)
        if kept is not None and kept.outputs_hold and not sink.werror:
            done = _write_kept(kept, path, sink, options)           # its outputs, as they were
            if done is not None:
                return done
        before = len(sink.diagnostics)
        with kept.recording(sink) if kept is not None else contextlib.nullcontext():
            with stage("lower"):
                definition = Span.of_file(str(path))
                if kept is not None and kept.header is not None and kept.model_holds(sink, definition):
                    if kept.force:                                 # its program, the ops run anew
                        program = kept.replay_program(sink)
                        kept.program_done()
                        program, robot = _robot(program, path, sink, options)
                        kept.front_end_done()
                    else:
                        program, robot = kept.replay_model(sink)   # its program and robot
                else:
                    program, robot = _program_and_robot(path, sink, options,
                                                        kept.program_done if kept is not None else None)
                    if kept is not None:
                        kept.front_end_done()
            if program is None or robot is None:
                return Result(program)
            model_end = len(sink.diagnostics)
            from mpc.backends.empty_meshes import check_empty
            from mpc.backends.solid_checks import check_closed

            with stage("apply ops"):
                check_closed(robot, sink, program.span)  # meshes that an op left open (W0582)
                check_empty(robot, sink, program.span)   # mesh files without triangles (W0505)
            if kept is not None and not (kept.model_used or kept.program_used) and mesh_worker.active():
                # the model it keeps, encoded while the worker starts on the meshes
                meanwhile.later(functools.partial(kept.encode_model, program, robot))
            out = _out(options, program.modelname)
            with stage("write"):
                written = emit(program, robot, out, sink, options.target)  # emit, rename into place
    finally:
        mesh_worker.stop()
        meanwhile.drop()
    if not written:
        return Result(program, robot)
    if kept is not None:
        with stage("keep"):                                    # for the next build
            kept.keep(program, robot, sink.diagnostics[before:model_end], out, sink.diagnostics[model_end:])
    return Result(program, robot, out)


def _first_build(path: Path, options: Options) -> bool:
    """Whether the build is sure to read its definition and most likely to make meshes: no build
    of the definition is kept (its first, or the cache was emptied), and it may make them in a
    process beside it (core/cores.py). A pipeline's builds (`options.defaults`) are not kept."""
    from mpc.compiler.build_cache import kept_folder
    from mpc.core.cores import forks_beside

    return (options.defaults is None and options.models is None and forks_beside()
            and not (kept_folder(path) / "entry").exists())


def _write_kept(kept: KeptBuild, path: Path, sink: Sink, options: Options) -> Result | None:
    """The kept outputs written into place, their diagnostics said again; None (nothing said)
    when one of them is damaged: the build runs."""
    out = _out(options, kept.modelname)
    own = Sink()
    with stage("write"):
        written = into_place(out, own, kept.span, kept.write_outputs)
    if not written and not own.diagnostics:
        kept.drop_outputs()
        return None
    if written:
        kept.replay_outputs(sink)
    for diagnostic in own.diagnostics:  # E0660: the output folder cannot be written
        sink.report(diagnostic)
    return Result(out=out, model=functools.partial(_kept_model, kept, path, options)) if written else Result()


def _kept_model(kept: KeptBuild, path: Path, options: Options) -> tuple[Program | None, Robot | None]:
    """The program and robot of a build that wrote its kept outputs; the front end's, its
    diagnostics already said, when the entry does not hold them (one changed in the cache)."""
    from mpc.compiler.kept_values import BadValue

    try:
        return kept.model()
    except BadValue:
        return _program_and_robot(path, Sink(), options)


def _out(options: Options, modelname: str) -> Path:
    """The output folder: `-o`, else build/<modelname> in the working folder."""
    return options.out or Path("build") / modelname


def _program_and_robot(path: Path, sink: Sink, options: Options,
                       program_done: Callable[[], None] | None = None,
                       ) -> tuple[Program | None, Robot | None]:
    """The front end and the ops: (program, robot), either None after errors. `program_done`
    is called when the front end has said all it says."""
    from mpc.backends import mesh_worker
    from mpc.core.cores import forks_beside

    if forks_beside():
        mesh_worker.start()  # imports numpy while the front end runs, then makes the meshes it is given
    from mpc.compiler.front_end import input_loader, load_program

    try:
        loader = input_loader(sink, options, (resolved(path),))
        program = load_program(path, sink, options, Severity.ERROR, loader)  # front end
    except OSError as e:
        return _unreadable(path, sink, e)
    if program is not None and mesh_worker.active():
        from mpc.backends.meshes import likely_tasks

        mesh_worker.offer(likely_tasks(loader.loaded(), program.exports))
    if program_done is not None:
        program_done()
    if program is not None and not options.post_processing:  # --no-post-processing
        from dataclasses import replace

        from mpc.ir.program import CommandExport

        program = replace(program, exports=tuple(e for e in program.exports
                                                 if not isinstance(e, CommandExport)))
    return _robot(program, path, sink, options, loader)


def _robot(program: Program | None, path: Path, sink: Sink, options: Options,
           loader: InputLoader | None = None) -> tuple[Program | None, Robot | None]:
    """The program's inputs read and its ops run: (program, robot), either None after errors.

    loader: the front end's, which read the inputs for their names and said what their readers
    say. Without it (the program is a kept build's, whose diagnostics were said again) the
    inputs are read anew, and what their readers say is said only with an error: the front end
    that made the program said it."""
    from mpc.compiler.inputs import InputLoader
    from mpc.compiler.ops_run import apply

    if program is None:
        return None, None
    quiet = Sink()
    loader = loader or InputLoader(quiet, options, (resolved(path),), build=_derived_base)
    try:
        with stage("apply ops"):                                          # read inputs, apply ops
            robot = apply(program, sink, loader)
    except OSError as e:
        return _unreadable(path, sink, e)
    if quiet.has_errors():
        for diagnostic in quiet.diagnostics:
            sink.report(diagnostic)
    return program, robot


def _derived_base(path: Path, sink: Sink, options: Options, stack: tuple[Path, ...]) -> Robot | None:
    """A derived_base definition built by the front end, for a loader made without it."""
    from mpc.compiler.front_end import build

    return build(path, sink, options, stack)


def _unreadable(path: Path, sink: Sink, error: OSError) -> tuple[None, None]:
    """What the readers do not report themselves (a name too long, say)."""
    sink.error(Span.of_file(str(path)), "E0661", describe(error, "read an input of the model"))
    return None, None
