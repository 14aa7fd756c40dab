"""Passes over an ir.Program, run in the order of `PASSES`.

A pass is `def name(program: Program, ctx: PassContext) -> Program`: it reports
through `ctx.sink` and returns a new program, or the same one when nothing changed.
It never mutates its input.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from mpc.compiler.diagnostics import Severity, Sink
from mpc.ir.names import Names
from mpc.ir.program import Input, Program


def _unknown(_: Input) -> Names | None:
    return None


@dataclass
class PassContext:
    """What every pass may use: the diagnostics sink, the input models' names, and whether
    what compiling does not support yet is an error (compile) or a warning (check)."""

    sink: Sink
    input_names: Callable[[Input], Names | None] = field(default=_unknown)
    later: Severity = Severity.ERROR


Pass = Callable[[Program, PassContext], Program]

from mpc.compiler.passes.check_names import check_names  # noqa: E402
from mpc.compiler.passes.drop_dead_ops import drop_dead_ops  # noqa: E402
from mpc.compiler.passes.fold_renames import fold_renames  # noqa: E402
from mpc.compiler.passes.order_ops import order_ops  # noqa: E402
from mpc.compiler.passes.resolve_inputs import resolve_inputs  # noqa: E402

# The order matters: names are checked on the program the others leave (ordered, folded, with
# no dead op), so that a report points at what will run.
PASSES: tuple[Pass, ...] = (resolve_inputs, order_ops, fold_renames, drop_dead_ops, check_names)


def run_passes(program: Program, ctx: PassContext) -> Program:
    for p in PASSES:
        errors = ctx.sink.error_count
        program = p(program, ctx)
        if ctx.sink.error_count > errors:  # later passes would only repeat the consequences
            break
    return program
