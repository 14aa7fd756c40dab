"""order_ops: put a program's ops in the language's order (specs/passes.md "Order of operations").

Input: a Program whose ops may be written in any order (an IR file). Output: the same ops in
the order of their phases (`Op.phase`), stably within a phase; the parts of the assembly depth
first, each part's own steps before its children, each child before its attaching. What it
does not do: check names (check_names) or drop ops (drop_dead_ops).

Lowering writes ops in this order already. An IR file written in another order is reordered
with a warning (W0330) when every op that moves passes only ops it is independent of: ops of
other parts of the assembly, or a pair the language declares independent (`remove_beyond` and
`take_leaf` keep the same links in either order; every other op keeps the robot's name).
Otherwise moving could change what the program means, and the file is refused (E0330),
naming both lines; a refused program is not reordered, and gets no W0330.

    op take_leaf link="forearm" @ arm.ir:4
    op remove_beyond links=["wrist"] @ arm.ir:5
    → warning[W0330]: remove_beyond (line 5) runs before take_leaf (line 4): …
"""

from __future__ import annotations

from dataclasses import replace

from mpc.compiler.passes.context import PassContext
from mpc.ir.ops import ROOT, Op, Phase
from mpc.ir.program import Program

# Pairs of phases whose ops on one part give the same robot in either order.
INDEPENDENT = frozenset({frozenset({Phase.REMOVE_BEYOND, Phase.TAKE_LEAF})})
# Phases whose ops give the same robot before or after an op of any other phase (the robot's
# name is kept by every other op).
INDEPENDENT_OF_ALL = frozenset({Phase.ROBOT_NAME})


def language_order(ops: tuple[Op, ...]) -> tuple[Op, ...]:
    """The ops in the language's order; ops of parts no attaching reaches go last, as written."""
    steps: dict[str, list[Op]] = {}
    attaches: dict[str, list[Op]] = {}
    robot: list[Op] = []
    for op in ops:
        if not op.phase().assembly:
            robot.append(op)
        elif op.phase() is Phase.ATTACH:
            attaches.setdefault(op.part, []).append(op)
        else:
            steps.setdefault(op.part, []).append(op)
    ordered: list[Op] = []
    placed: set[str] = set()

    def part(name: str) -> None:
        if name in placed:  # an attaching that closes a circle of parts: left as written below
            return
        placed.add(name)
        ordered.extend(sorted(steps.get(name, ()), key=lambda op: op.phase()))
        for attach in attaches.get(name, ()):
            part(attach.child)  # type: ignore[attr-defined]
            ordered.append(attach)

    part(ROOT)
    done = {id(op) for op in ordered}
    ordered.extend(op for op in ops if op.phase().assembly and id(op) not in done)
    ordered.extend(sorted(robot, key=lambda op: op.phase()))
    return tuple(ordered)


def independent(a: Op, b: Op) -> bool:
    """Whether `a` and `b` give the same result in either order."""
    return not set(a.parts()) & set(b.parts()) or _independent_phases(a, b)


def _independent_phases(a: Op, b: Op) -> bool:
    phases = frozenset({a.phase(), b.phase()})
    return phases in INDEPENDENT or (len(phases) == 2 and bool(phases & INDEPENDENT_OF_ALL))


def order_ops(program: Program, ctx: PassContext) -> Program:
    ordered = language_order(program.ops)
    if all(a is b for a, b in zip(ordered, program.ops, strict=True)):
        return program
    position = {id(op): i for i, op in enumerate(ordered)}
    refused = False
    moved: list[tuple[Op, Op]] = []  # (op, the first op of its part it now precedes)
    for i, later in enumerate(program.ops):  # `later`: written after the ops it now precedes
        passed = [op for op in program.ops[:i] if position[id(op)] > position[id(later)]]
        if not passed:
            continue
        clash = next((op for op in passed if not independent(op, later)), None)
        if clash is not None:
            ctx.sink.error(later.span, "E0330", f"{later.kind} (line {later.span.line}) is written "
                           f"after {clash.kind} (line {clash.span.line}), but the language runs it "
                           "first, and the two do not give the same robot in either order",
                           hint="write the ops in the language's order (specs/passes.md)")
            refused = True
            continue
        # Moving past other parts' ops, or past the robot's name, changes nothing one could see.
        swapped = [op for op in passed if set(op.parts()) & set(later.parts())
                   and not {op.phase(), later.phase()} & INDEPENDENT_OF_ALL]
        if swapped:
            moved.append((later, min(swapped, key=lambda op: position[id(op)])))
    if refused:  # nothing is reordered: saying what moved would be wrong
        return program
    for later, first in moved:
        ctx.sink.warning(later.span, "W0330", f"{later.kind} (line {later.span.line}) runs "
                         f"before {first.kind} (line {first.span.line}), in the language's order",
                         hint="the program is reordered; write it in that order to silence this")
    return replace(program, ops=ordered)
