"""compiler/expr_syntax.py, the hand-written parser of grammar/expr.lark, gives what lark's LALR
parser of the grammar gives (the parser mpc used before; lark stays for grammar/ir.lark): the
same node trees with the same offsets, and the same syntax errors at the same offsets, on
generated expressions, valid and broken."""

from __future__ import annotations

import random

import pytest
from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken
from lark.tree import Meta

from mpc.compiler.expr_nodes import Binary, Call, Name, Node, Num, Unary
from mpc.compiler.expr_syntax import ExprSyntaxError, parse_text

HINTS = {"^": "use ** for powers", "π": "write pi"}


@v_args(meta=True, inline=True)
class _ToNodes(Transformer[Token, Node]):
    """lark's parse tree of expr.lark → the nodes (as compiler/expr_syntax.py made them with lark)."""

    def number(self, meta: Meta, tok: Token) -> Num:
        return Num(float(tok), meta.start_pos, meta.end_pos)

    def name(self, meta: Meta, tok: Token) -> Name:
        return Name(str(tok), meta.start_pos, meta.end_pos)

    def unary(self, meta: Meta, op: Token, operand: Node) -> Unary:
        return Unary(str(op), operand, meta.start_pos, meta.end_pos)

    def binary(self, meta: Meta, left: Node, op: Token, right: Node) -> Binary:
        return Binary(str(op), left, right, meta.start_pos, meta.end_pos)

    def call(self, meta: Meta, func: Token, args: tuple[Node, ...] | None) -> Call:
        return Call(str(func), args or (), meta.start_pos, meta.end_pos)

    def args(self, meta: Meta, *args: Node) -> tuple[Node, ...]:
        return args


LARK = Lark.open_from_package("mpc.grammar", "expr.lark", parser="lalr", propagate_positions=True)


def by_lark(text: str) -> Node | tuple[int, str, str | None]:
    """The node tree lark gives, or its syntax error as (offset, 'unexpected …', hint)."""
    try:
        return _ToNodes().transform(LARK.parse(text))
    except UnexpectedInput as e:
        if isinstance(e, UnexpectedCharacters):
            char = text[e.pos_in_stream]
            return e.pos_in_stream, f"unexpected '{char}'", HINTS.get(char)
        if isinstance(e, UnexpectedToken) and e.token.type != "$END":
            return e.token.start_pos or 0, f"unexpected '{e.token}'", None
        return len(text.rstrip()), "unexpected end of expression", None


def by_hand(text: str) -> Node | tuple[int, str, str | None]:
    try:
        return parse_text(text)
    except ExprSyntaxError as e:
        return e.offset, e.found, e.hint


PIECES = ["1", "2.5", ".5", "3.", "1e3", "2E-1", "x", "pi", "sqrt", "atan2", "_a1", "+", "-", "*", "/",
          "**", "(", ")", ",", " ", "\n", "^", "π", "$", ".", "e", "()", "(1)", "f(", "2*pi"]


def generated(count: int, seed: int) -> list[str]:
    rng = random.Random(seed)
    return ["".join(rng.choice(PIECES) for _ in range(rng.randint(0, 12))) for _ in range(count)]


def valid(rng: random.Random, depth: int = 0) -> str:
    """A random expression of the grammar."""
    choice = rng.randint(0, 6 if depth < 4 else 1)
    atom = rng.choice(["1", "2.5", ".5", "1e-3", "pi", "x"])
    if choice <= 1:
        return atom
    if choice == 2:
        return rng.choice(["-", "+", "- "]) + valid(rng, depth + 1)
    if choice == 3:
        return f"({valid(rng, depth + 1)})"
    if choice == 4:
        args = ", ".join(valid(rng, depth + 1) for _ in range(rng.randint(0, 3)))
        return f"{rng.choice(['sqrt', 'f', 'max'])}({args})"
    op = rng.choice(["+", "-", "*", "/", "**", " ** ", " * "])
    return valid(rng, depth + 1) + op + valid(rng, depth + 1)


@pytest.mark.parametrize("text", ["-2**x", "f(1, (2))", "g()", "(1+2)*3", "-(1)", "((1))", "2**-1",
                                  "2 3", "2*/pi", "(1+2))", "2^3", "π", "1+", "", "  ", "f(1,)",
                                  "2pi", "1..2", "(", "f(,1)", "x(1)(2)", "-(-(-1))**2"])
def test_the_parser_gives_what_lark_gives(text: str) -> None:
    assert by_hand(text) == by_lark(text)


def test_generated_broken_expressions() -> None:
    texts = generated(6000, seed=34)
    assert sum(isinstance(by_lark(t), tuple) for t in texts) > 3000  # mostly broken ones
    assert [by_hand(t) for t in texts] == [by_lark(t) for t in texts]


def test_generated_valid_expressions() -> None:
    rng = random.Random(6)
    texts = [valid(rng) for _ in range(3000)]
    assert not any(isinstance(by_lark(t), tuple) for t in texts)
    assert [by_hand(t) for t in texts] == [by_lark(t) for t in texts]
