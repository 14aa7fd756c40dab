"""Expression text → typed nodes with lark (grammar/expr.lark); imported only for strings.

Kept apart from compiler/expr.py so that definitions whose numbers are plain numbers
never import lark (`mpc check` runs on every keystroke).
"""

from __future__ import annotations

from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.tree import Meta

from mpc.compiler.expr_nodes import Binary, Call, Name, Node, Num, Unary

_CHAR_HINTS = {"^": "use ** for powers", "π": "write pi"}


def load() -> Lark:
    return Lark.open_from_package("mpc.grammar", "expr.lark", parser="lalr", propagate_positions=True)


@v_args(meta=True, inline=True)
class ExprTransformer(Transformer[Token, Node]):
    """Parse tree of expr.lark → typed nodes; shape only, no checks of names or arity."""

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


def syntax_error(e: UnexpectedInput, text: str) -> tuple[int, str, str | None]:
    """(offset, 'unexpected …', hint) of a lark error."""
    if isinstance(e, UnexpectedCharacters):
        char = text[e.pos_in_stream]
        return e.pos_in_stream, f"unexpected '{char}'", _CHAR_HINTS.get(char)
    if isinstance(e, UnexpectedToken) and e.token.type != "$END":
        return e.token.start_pos or 0, f"unexpected '{e.token}'", None
    assert isinstance(e, UnexpectedToken | UnexpectedEOF), e
    return len(text.rstrip()), "unexpected end of expression", None
