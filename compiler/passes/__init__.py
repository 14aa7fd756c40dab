"""Passes over an ir.Program, run in the order of `PASSES`.

A pass is `def name(program: Program, ctx: PassContext) -> Program`: it reports
through `ctx.sink` and returns a new program, or the same one when nothing changed.
It never mutates its input.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from mpc.compiler.diagnostics import Sink
from mpc.ir.program import Program


@dataclass
class PassContext:
    """What every pass may use: the diagnostics sink."""

    sink: Sink


Pass = Callable[[Program, PassContext], Program]

from mpc.compiler.passes.resolve_inputs import resolve_inputs  # noqa: E402

PASSES: tuple[Pass, ...] = (resolve_inputs,)


def run_passes(program: Program, ctx: PassContext) -> Program:
    for p in PASSES:
        program = p(program, ctx)
    return program
