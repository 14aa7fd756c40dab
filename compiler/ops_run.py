"""A program's ops run on its input models → its robot.

Apart from the front end (compiler/front_end.py): a build whose program comes from the build
cache (compiler/build_cache.py, `mpc compile --force` on unchanged definitions) reads its inputs
and runs its ops without importing the definition's schema.
"""

from __future__ import annotations

from dataclasses import replace

from mpc.compiler.inputs import InputLoader
from mpc.core.diagnostics import Sink
from mpc.ir.names import Names
from mpc.ir.ops import ROOT, Attach, Effects, LoadModel
from mpc.ir.ops.assembly import r2r_origin
from mpc.ir.program import Program
from mpc.ir.robot import Robot


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
