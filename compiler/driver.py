"""Check or compile one model definition: YAML on disk → diagnostics, or model files.

`compile_model` reads as a list of named phases; each stops the build when it
reported an error. Outputs are built in a temporary folder beside the output and
renamed into place only when everything succeeded, so a failed build leaves the
previous outputs untouched.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from mpc.backends.packages import PackageResolver
from mpc.compiler import inherit, schema, source
from mpc.compiler.diagnostics import Severity, Sink
from mpc.compiler.inputs import InputLoader
from mpc.compiler.lower import lower
from mpc.compiler.passes import PassContext, run_passes
from mpc.compiler.passes.check_names import symbolic
from mpc.ir.names import Names
from mpc.ir.ops import ROOT, Attach, Effects, LoadModel
from mpc.ir.ops.assembly import r2r_origin
from mpc.ir.program import CommandExport, Export, JointLimitsExport, Program, RobotExport, SubmodelExport
from mpc.ir.robot import Robot
from mpc.ir.span import Span


@dataclass
class Options:
    """How to compile: where outputs go, how packages are found."""

    out: Path | None = None
    resolver: PackageResolver = field(default_factory=PackageResolver)
    # Pipeline runs (compiler/pipeline/): the pipeline's defaults, applied to each definition
    # after its own defaults chain; and where the output goes once the runner moves it from
    # `out` (a staging folder) into place, which post_processing commands see as their target.
    defaults: Callable[[source.Document], source.Document] | None = None
    target: Path | None = None


@dataclass
class Result:
    """What a compilation produced: the program, the robot and the output folder."""

    program: Program | None = None
    robot: Robot | None = None
    out: Path | None = None


def front_end(path: Path, sink: Sink, options: Options, later: Severity = Severity.ERROR,
              loader: InputLoader | None = None, doc: source.Document | None = None) -> Program | None:
    """Load, resolve defaults, validate, lower and run passes; the program or None.

    later: how to report what compiling does not support yet (check: a warning).
    doc: the file, when the caller loaded it already.
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
    if program is None:
        return None
    loader = loader or InputLoader(sink, options, (path.resolve(),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later))  # run passes
    return None if sink.has_errors() else program


def load_program(path: Path, sink: Sink, options: Options, later: Severity = Severity.ERROR,
                 loader: InputLoader | None = None) -> Program | None:
    """The program of a definition (YAML) or of an IR file (`.ir`, as `--emit ir` prints)."""
    if path.suffix != ".ir":
        return front_end(path, sink, options, later, loader)
    from mpc.ir.text import parse

    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        sink.error(Span.of_file(str(path)), "E0601", f"cannot read '{path}': {e.strerror}")
        return None
    program = parse(text, str(path), sink)                              # parse the IR
    if program is None:
        return None
    loader = loader or InputLoader(sink, options, (path.resolve(),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later))  # run passes
    return None if sink.has_errors() else program


def names_of(path: Path, sink: Sink, options: Options, stack: tuple[Path, ...]) -> Names | None:
    """The names of another definition's output, found without building it."""
    loader = InputLoader(sink, options, stack, symbolic=True)
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
    loader = InputLoader(sink, options, stack)
    program = front_end(path, sink, options, Severity.ERROR, loader)
    return apply(program, sink, loader) if program else None


def check_file(path: Path, sink: Sink, options: Options) -> None:
    """Everything `mpc check` does for one file; nothing is written.

    A model definition goes through the front end with names checked; a pipeline file
    is validated and each of its model definitions checked.
    """
    if path.suffix == ".ir":
        load_program(path, sink, options, Severity.WARNING)
        return
    doc = source.load(path, sink)
    if doc is None:
        return
    if isinstance(doc.data, dict) and "pipeline" in doc.data:
        from mpc.compiler.pipeline.plan import check_pipeline

        check_pipeline(path, sink, lambda model, defaults: front_end(
            model, sink, replace(options, defaults=defaults), Severity.WARNING))
        return
    front_end(path, sink, options, Severity.WARNING, doc=doc)


def emit(program: Program, robot: Robot, out: Path, sink: Sink, target: Path | None = None) -> bool:
    """Write every export into a fresh folder next to `out`, then swap it into place."""
    from mpc.backends import BACKENDS

    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".mpc-tmp", dir=out.parent))
    try:
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
                    model, folder = submodels[export.submodel], staging / "submodels" / export.submodel
                if isinstance(export, JointLimitsExport) and export.joints_of:
                    model = submodels[export.joints_of]  # its joints, written where the entry is
                if model is not None and export.add_floating_base:
                    model = _floating(model, export, sink)
                if model is not None and getattr(export, "correct_inertials", False):
                    model = _physical(model, export, sink)
                if model is None:
                    continue
            folder.mkdir(parents=True, exist_ok=True)
            BACKENDS[export.type]().emit(model, export, folder, sink)
        if sink.has_errors():
            return False
        _replace(staging, out)
        return True
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


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


def _replace(new: Path, out: Path) -> None:
    """Put `new` where `out` is; the old `out` disappears only after `new` is in place."""
    if not out.exists():
        os.replace(new, out)
        return
    old = out.with_name(f".{out.name}.mpc-old-{os.getpid()}")
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
    loader = InputLoader(sink, options, (path.resolve(),))
    result.program = load_program(path, sink, options, Severity.ERROR, loader)  # front end
    if result.program is None:
        return result
    result.robot = apply(result.program, sink, loader)   # read inputs, apply ops
    if result.robot is None:
        return result
    from mpc.backends.solid_checks import check_closed

    check_closed(result.robot, sink, result.program.span)  # meshes that an op left open (W0582)
    out = options.out or Path("build") / result.program.modelname
    if emit(result.program, result.robot, out, sink, options.target):  # emit, rename into place
        result.out = out
    return result
