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
from mpc.compiler.passes.resolve_inputs import resolve_inputs  # noqa: E402

PASSES: tuple[Pass, ...] = (resolve_inputs, check_names)


def run_passes(program: Program, ctx: PassContext) -> Program:
    for p in PASSES:
        errors = ctx.sink.error_count
        program = p(program, ctx)
        if ctx.sink.error_count > errors:  # later passes would only repeat the consequences
            break
    return program
