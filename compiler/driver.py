"""Check or compile one model definition: YAML on disk → diagnostics, or model files.

`compile_model` reads as a list of named phases; each stops the build when it
reported an error. Outputs are built in a temporary folder beside the output and
renamed into place only when everything succeeded, so a failed build leaves the
previous outputs untouched.
"""

from __future__ import annotations

import glob
import os
import shutil
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from mpc.compiler import inherit, schema
from mpc.compiler.inputs import InputLoader, Options
from mpc.compiler.lower import lower
from mpc.compiler.passes import PassContext, run_passes
from mpc.compiler.passes.check_names import symbolic
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Severity, Sink
from mpc.core.files import OutsideOutput, confined, describe
from mpc.core.profile import stage
from mpc.core.span import Span
from mpc.ir.names import Names
from mpc.ir.ops import ROOT, Attach, Effects, LoadModel
from mpc.ir.ops.assembly import r2r_origin
from mpc.ir.program import CommandExport, Export, JointLimitsExport, Program, RobotExport, SubmodelExport
from mpc.ir.robot import Robot


@dataclass
class Result:
    """What a compilation produced: the program, the robot and the output folder."""

    program: Program | None = None
    robot: Robot | None = None
    out: Path | None = None


def front_end(path: Path, sink: Sink, options: Options, later: Severity = Severity.ERROR,
              loader: InputLoader | None = None, doc: source.Document | None = None,
              passes: bool = True) -> Program | None:
    """Load, resolve defaults, validate, lower and run passes; the program or None.

    later: how to report what compiling does not support yet (check: a warning).
    doc: the file, when the caller loaded it already.
    passes: False: the program as lowered (`--emit ir-lowered`), the passes not run.
    """
    doc = doc or source.load(path, sink)                                  # load sources
    if doc is None:
        return None
    doc = inherit.resolve(doc, path, sink)                                # merge defaults
    if doc is None:
        return None
    if options.defaults is not None:
        doc = options.defaults(doc)                                       # pipeline defaults
    ast = schema.validate(doc, sink)                                      # validate schema
    if ast is None:
        return None
    program = lower(ast, path.resolve().parent, sink, options.resolver, later)  # lower
    if program is None or not passes:
        return None if sink.has_errors() else program
    loader = loader or input_loader(sink, options, (path.resolve(),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later))  # run passes
    loader.report_missing_meshes()                                        # check: mesh files
    return None if sink.has_errors() else program


def load_program(path: Path, sink: Sink, options: Options, later: Severity = Severity.ERROR,
                 loader: InputLoader | None = None, passes: bool = True) -> Program | None:
    """The program of a definition (YAML) or of an IR file (`.ir`, as `--emit ir` prints);
    passes: False: as lowered or parsed, the passes (compiler/passes/) not run."""
    if path.suffix != ".ir":
        return front_end(path, sink, options, later, loader, passes=passes)
    from mpc.ir.text import parse

    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        sink.error(Span.of_file(str(path)), "E0601", f"cannot read '{path}': {e.strerror}")
        return None
    program = parse(text, str(path), sink)                              # parse the IR
    if program is None or not check_output_names(program, sink):
        return None
    if not passes:
        return program
    loader = loader or input_loader(sink, options, (path.resolve(),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later))  # run passes
    return None if sink.has_errors() else program


def check_output_names(program: Program, sink: Sink) -> bool:
    """The names of an IR program that become file names, checked as the schema checks
    them in YAML (E0250): IR text comes without a schema."""
    from mpc.core.files import name_problem

    named = [("robotname", program.robotname, program.span, False),
             ("modelname", program.modelname, program.span, False)]
    for export in program.exports:
        for field_, folders in (("filename", False), ("file_name", True), ("name", False)):
            value = getattr(export, field_, "")
            if isinstance(value, str) and value:
                named.append((field_, value, export.span, folders))
    ok = True
    for field_, value, span, folders in named:
        if why := name_problem(value, folders=folders):
            sink.error(span, "E0250", f"'{field_}': cannot name a file in the output: {why}")
            ok = False
    return ok


def input_loader(sink: Sink, options: Options, stack: tuple[Path, ...],
                 symbolic: bool = False) -> InputLoader:
    """The loader of one compilation's inputs, which builds derived_base definitions (or finds
    their names, `symbolic`) with this module's front end."""
    return InputLoader(sink, options, stack, symbolic, build=build, names_of=names_of)


def names_of(path: Path, sink: Sink, options: Options, stack: tuple[Path, ...]) -> Names | None:
    """The names of another definition's output, found without building it."""
    loader = input_loader(sink, options, stack, symbolic=True)
    program = front_end(path, sink, options, Severity.WARNING, loader)
    return symbolic(program, PassContext(sink, loader.names, Severity.WARNING)) if program else None


def apply(program: Program, sink: Sink, loader: InputLoader) -> Robot | None:
    """Read the inputs and run the ops; the robot or None."""
    parts: dict[str, Robot] = {}
    originals: dict[str, Robot] = {}
    for op in program.ops:
        if isinstance(op, LoadModel):
            inp = program.inputs[op.input]
            robot = loader.robot(inp)
            if robot is None:
                return None
            if not inp.smurf_data:
                from mpc.ir.smurf_data import without_smurf_data

                robot = without_smurf_data(robot)
            parts[op.part] = originals[op.part] = robot
        elif isinstance(op, Attach):
            op = op.resolved(Names.of(parts[op.part]), Names.of(parts[op.child]))
            if op.r2r is not None:
                op = replace(op, origin=r2r_origin(op, originals[op.part], originals[op.child]))
            from mpc.ir.reroot import RerootError

            try:
                parts[op.part] = op.attach(parts[op.part], parts.pop(op.child))
            except RerootError as error:
                sink.error(op.span_of("child_link"), "E0551", f"cannot re-root the child model at "
                           f"'{op.child_link}' to attach it there: {error}")
                return None
        else:
            parts[op.part] = op.apply(parts[op.part], Effects(sink, op))
    return None if sink.has_errors() else parts[ROOT]


def build(path: Path, sink: Sink, options: Options, stack: tuple[Path, ...]) -> Robot | None:
    """The robot another definition describes, built in memory (for derived_base)."""
    loader = input_loader(sink, options, stack)
    program = front_end(path, sink, options, Severity.ERROR, loader)
    return apply(program, sink, loader) if program else None


def check_file(path: Path, sink: Sink, options: Options, doc: source.Document | None = None) -> None:
    """Everything `mpc check` does for one model definition (or IR file); nothing is written.

    `doc` is the file already loaded, when the caller had to read it to know what it is
    (pipeline/plan.py's check_file, which also takes pipeline files).
    """
    try:
        if path.suffix == ".ir":
            load_program(path, sink, options, Severity.WARNING)
            return
        doc = doc or source.load(path, sink)
        if doc is not None:
            front_end(path, sink, options, Severity.WARNING, doc=doc)
    except OSError as e:
        sink.error(Span.of_file(str(path)), "E0661", describe(e, "read an input of the model"))


def emit(program: Program, robot: Robot, out: Path, sink: Sink, target: Path | None = None) -> bool:
    """Write every export into a fresh folder next to `out`, then swap it into place.

    An OSError (a read-only or full disk, a file where a folder must be, a name too long)
    is E0660 naming the path and what was being done; a name that would lead out of the
    output folder is E0653. Either way the previous output stays as it was.
    """
    step = "make the output's folder"
    staging: Path | None = None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_staging(out)
        step = "make a staging folder"
        staging = Path(tempfile.mkdtemp(prefix=_staging_prefix(out), suffix=".mpc-tmp", dir=out.parent))
        step = "write the output"
        if not _emit_exports(program, robot, staging, out, sink, target):
            return False
        step = "move the build into place"
        replace_folder(staging, out)
        return True
    except OSError as e:
        sink.error(program.span, "E0660",
                   f"{describe(e, step)}; the previous output is unchanged")
        return False
    except OutsideOutput as e:
        sink.error(program.span, "E0653", f"{e}; nothing is written there")
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
    from mpc.backends import BACKENDS

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
            BACKENDS[export.type]().emit(model, export, folder, sink)
    return not sink.has_errors()


def _floating(robot: Robot, export: Export, sink: Sink) -> Robot | None:
    """`robot` with a floating base (ir/floating.py), or None with E0505."""
    from mpc.ir.floating import with_floating_base

    floating = with_floating_base(robot)
    if floating is None:
        sink.error(export.span, "E0505", "add_floating_base needs the names 'world' and "
                   "'floating_base', which the robot uses already")
    return floating


def _physical(robot: Robot, export: Export, sink: Sink) -> Robot:
    """`robot` with its non-physical inertials made physical (ir/physical.py); W0530 names them."""
    from mpc.ir.physical import correct_inertials

    robot, changed = correct_inertials(robot)
    if changed:
        more = f" and {len(changed) - 8} more" if len(changed) > 8 else ""
        shown = ", ".join(f"'{n}'" for n in changed[:8]) + more
        sink.warning(export.span, "W0530", f"correct_inertials made the inertials of {len(changed)} "
                     f"link{'s' if len(changed) > 1 else ''} physical: {shown}")
    return robot


def replace_folder(new: Path, out: Path) -> None:
    """Put `new` where `out` is; the old `out` disappears only after `new` is in place."""
    if not out.exists():
        os.replace(new, out)
        return
    old = out.with_name(f".{out.name[:100]}.mpc-old-{os.getpid()}")
    os.replace(out, old)
    try:
        os.replace(new, out)
    except OSError:
        os.replace(old, out)
        raise
    shutil.rmtree(old, ignore_errors=True)


def compile_model(path: Path, sink: Sink, options: Options) -> Result:
    """Compile the definition at `path`; diagnostics go to `sink`."""
    result = Result()
    try:
        loader = input_loader(sink, options, (path.resolve(),))
        with stage("lower"):
            result.program = load_program(path, sink, options, Severity.ERROR, loader)  # front end
        if result.program is None:
            return result
        with stage("apply ops"):
            result.robot = apply(result.program, sink, loader)   # read inputs, apply ops
    except OSError as e:  # what the readers do not report themselves (a name too long, say)
        sink.error(Span.of_file(str(path)), "E0661", describe(e, "read an input of the model"))
        return Result()
    if result.robot is None:
        return result
    from mpc.backends.solid_checks import check_closed

    with stage("apply ops"):
        check_closed(result.robot, sink, result.program.span)  # meshes that an op left open (W0582)
    out = options.out or Path("build") / result.program.modelname
    with stage("write"):
        written = emit(result.program, result.robot, out, sink, options.target)
    if written:  # emit, rename into place
        result.out = out
    return result
