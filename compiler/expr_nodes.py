"""The syntax tree of a numeric expression (compiler/expr.py evaluates it, compiler/expr_syntax.py
builds it from lark's parse tree). Only the nodes: no parsing, no evaluation.
"""

from __future__ import annotations

from mpc.core.record import record

# Nodes. `start`/`end` are 0-based offsets into the expression text (end exclusive);
# the evaluator turns them into file spans, since the parser never sees the file.

@record(slots=True)
class Num:
    """A number literal; value: its float value."""

    value: float
    start: int
    end: int


@record(slots=True)
class Name:
    """A bare name; id: as written (only the constants in CONSTANTS evaluate)."""

    id: str
    start: int
    end: int


@record(slots=True)
class Unary:
    """A sign applied to an operand; op: '+' or '-'."""

    op: str
    operand: Node
    start: int
    end: int


@record(slots=True)
class Binary:
    """left op right; op: one of + - * / **."""

    op: str
    left: Node
    right: Node
    start: int
    end: int


@record(slots=True)
class Call:
    """func(args...); func: the name as written, args: the argument expressions in order."""

    func: str
    args: tuple[Node, ...]
    start: int
    end: int


Node = Num | Name | Unary | Binary | Call
