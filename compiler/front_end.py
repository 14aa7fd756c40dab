"""A definition (or an IR file) → its program; nothing is written.

The front end loads the YAML, merges its defaults, validates it against the schema, lowers
it and runs the passes (compiler/passes/); compiler/ops_run.py reads the input models and runs
the program's ops on them. `mpc check` and `mpc lsp` stop after the front end; compiling
(compiler/driver.py) goes on to write the outputs, and imports this module only when its
build cache (compiler/build_cache.py) holds no program of the same inputs.
"""

from __future__ import annotations

from pathlib import Path

from mpc.compiler import inherit, schema
from mpc.compiler.inputs import InputLoader
from mpc.compiler.lower import lower
from mpc.compiler.ops_run import apply
from mpc.compiler.options import Options
from mpc.compiler.passes import PassContext, run_passes
from mpc.compiler.passes.check_names import symbolic
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Severity, Sink
from mpc.core.files import describe, resolved
from mpc.core.span import Span
from mpc.ir.names import Names
from mpc.ir.ops import LoadModel
from mpc.ir.program import Program
from mpc.ir.robot import Robot


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
    program = lower(ast, resolved(path).parent, sink, options.resolver, later)  # lower
    if program is None or not passes:
        return None if sink.has_errors() else program
    loader = loader or input_loader(sink, options, (resolved(path),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later, loader.name_span))  # run passes
    loader.report_missing_meshes()                                        # check: mesh files
    return None if sink.has_errors() else program


def check_inertials(program: Program, loader: InputLoader, sink: Sink) -> None:
    """`mpc check`: what an sdf or mjcf export without `correct_inertials` would refuse (E0504),
    on the inertials of the input model files as they are read. Only links that keep their name
    are seen, and none when an op combines or estimates inertias (removing a joint,
    estimate_missing_inertia): those need the built robot, which compiling checks."""
    from mpc.ir.program import MjcfExport, SdfExport

    exports = [e for e in program.exports  # a submodel's inertias are merged ones: compiling checks them
               if isinstance(e, SdfExport | MjcfExport) and not e.correct_inertials and not e.submodel]
    # by their kinds: importing the op classes would import modules `mpc check` need not load
    if not exports or any(op.kind in ("estimate_missing_inertia", "remove_joint") for op in program.ops):
        return
    names = symbolic(program, PassContext(Sink(), loader.names, Severity.WARNING))
    if names is None:
        return
    # files read for their names already; not a derived_base (built) or a repository (cloned)
    inputs = [program.inputs[op.input] for op in program.ops if isinstance(op, LoadModel)]
    for robot in (loader.robot(inp) for inp in inputs if inp.kind == "basefile"):
        if robot is None:
            continue
        for export in exports:
            if isinstance(export, SdfExport):
                from mpc.backends.sdf import check_inertials as sdformat

                sdformat(robot, sink, export.span, only=names.links)
            else:
                from mpc.backends.mjcf import check as mujoco

                mujoco(robot, sink, export.span, only=names.links)


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
    loader = loader or input_loader(sink, options, (resolved(path),), symbolic=later is Severity.WARNING)
    program = run_passes(program, PassContext(sink, loader.names, later, loader.name_span))  # run passes
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
            loader = input_loader(sink, options, (path.resolve(),), symbolic=True)
            program = front_end(path, sink, options, Severity.WARNING, loader, doc=doc)
            if program is not None:
                check_inertials(program, loader, sink)
    except OSError as e:
        sink.error(Span.of_file(str(path)), "E0661", describe(e, "read an input of the model"))
