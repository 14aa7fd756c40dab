"""Passes over an ir.Program, run in the order of `PASSES`.

A pass is `def name(program: Program, ctx: PassContext) -> Program`: it reports
through `ctx.sink` and returns a new program, or the same one when nothing changed.
It never mutates its input.
"""

from __future__ import annotations

from collections.abc import Callable

from mpc.compiler.passes.check_names import check_names
from mpc.compiler.passes.context import PassContext
from mpc.compiler.passes.drop_dead_ops import drop_dead_ops
from mpc.compiler.passes.fold_renames import fold_renames
from mpc.compiler.passes.order_ops import order_ops
from mpc.compiler.passes.resolve_inputs import resolve_inputs
from mpc.ir.program import Program

__all__ = ["PASSES", "Pass", "PassContext", "run_passes"]

Pass = Callable[[Program, PassContext], Program]

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
