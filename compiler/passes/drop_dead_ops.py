"""drop_dead_ops: remove an op whose effect a later cut of its part discards, with a warning.

Input: an ordered Program and the input models' names. Output: the program without the dead
ops, each reported (W0331) with the line of the op and of the cut that makes it pointless.
What it does not do: report unknown names (check_names does, on the program it returns), or
drop anything when an input's names are unknown.

A cut is `remove_beyond` or `take_leaf`. A cut is dead when the next cut of the same part,
with no renaming between them, leaves the same tree whether it ran or not: a `remove_beyond`
outside the subtree a later `take_leaf` keeps, or one that removes nothing. Edits of what a
later cut removes cannot occur: a part is cut before it is edited, and order_ops refuses a
program that edits a part before cutting it.

    assemble: {model: arm, remove_beyond: [hand], take_leaf: forearm}   # hand: not below forearm
    → warning[W0331]: remove_beyond (line 3) has no effect: after take_leaf (line 3) the robot is
      the same without it; it is dropped
"""

from __future__ import annotations

from dataclasses import replace

from mpc.compiler.passes.check_names import symbolic
from mpc.compiler.passes.context import PassContext
from mpc.core.diagnostics import Sink
from mpc.ir.names import Names
from mpc.ir.ops import Effects, Op, Phase
from mpc.ir.program import Program

CUTS = (Phase.REMOVE_BEYOND, Phase.TAKE_LEAF)


def _same_tree(a: Names, b: Names) -> bool:
    return a.links == b.links and a.root == b.root and a.joints == b.joints


def _discarded(before: Names, after: Names, cut: Op, cut_before: Names, cut_after: Names) -> bool:
    """Whether an earlier cut, which turned `before` into `after`, is pointless: `cut`, the
    next cut of the part (`cut_before` → `cut_after`), leaves the same tree without it."""
    return (_same_tree(after, cut_before)  # nothing between them renamed or cut
            and all(ref.name in before.all(ref.kind) for ref in cut.reads())
            and _same_tree(cut.effect(before, Effects(Sink(), cut)), cut_after))


def drop_dead_ops(program: Program, ctx: PassContext) -> Program:
    cut_parts = [op.part for op in program.ops if op.phase() in CUTS]
    if len(cut_parts) == len(set(cut_parts)):  # no part is cut twice: no cut can be dead
        return program
    seen: list[tuple[Op, Names, Names]] = []
    symbolic(program, replace(ctx, sink=Sink()), lambda op, before, after: seen.append((op, before, after)))
    dead: dict[int, Op] = {}
    for i, (op, before, after) in enumerate(seen):
        if op.phase() not in CUTS:
            continue
        for cut, cut_before, cut_after in seen[i + 1:]:
            if cut.part != op.part or cut.phase() not in CUTS:
                continue
            if _discarded(before, after, cut, cut_before, cut_after):
                dead[id(op)] = cut
            break  # only the first later cut: after it the names are those it left
    if not dead:
        return program
    for op in program.ops:
        cut = dead.get(id(op))
        if cut is not None:
            ctx.sink.warning(op.span, "W0331", f"{op.kind} (line {op.span.line}) has no effect: "
                             f"after {cut.kind} (line {cut.span.line}) the robot is the same "
                             "without it; it is dropped",
                             notes=((cut.span, f"the {cut.kind} that discards it"),),
                             hint=f"remove the {op.kind}")
    return replace(program, ops=tuple(op for op in program.ops if id(op) not in dead))
