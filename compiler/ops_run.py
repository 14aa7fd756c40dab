"""A program's ops run on its input models → its robot, and the loader of those inputs.

Apart from the front end (compiler/front_end.py), which it imports only to build a
`derived_base` definition or find its names: a build whose program comes from the build cache
(compiler/build_cache.py, `mpc compile --force` on unchanged definitions) reads its inputs and
runs its ops without importing the definition's schema.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from mpc.compiler.inputs import InputLoader
from mpc.compiler.options import Options
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.names import Names
from mpc.ir.ops import ROOT, Attach, Effects, LoadModel
from mpc.ir.ops.assembly import r2r_origin
from mpc.ir.program import Program
from mpc.ir.robot import Robot


def input_loader(sink: Sink, options: Options, stack: tuple[Path, ...],
                 symbolic: bool = False) -> InputLoader:
    """The loader of one compilation's inputs, which builds derived_base definitions (or finds
    their names, `symbolic`) with the front end."""
    return InputLoader(sink, options, stack, symbolic, build=build, names_of=names_of)


def names_of(path: Path, sink: Sink, options: Options, stack: tuple[Path, ...]) -> Names | None:
    """The names of another definition's output, found without building it."""
    from mpc.compiler.front_end import front_end
    from mpc.compiler.passes import PassContext
    from mpc.compiler.passes.check_names import symbolic

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
    from mpc.compiler.front_end import front_end

    loader = input_loader(sink, options, stack)
    program = front_end(path, sink, options, Severity.ERROR, loader)
    return apply(program, sink, loader) if program else None
