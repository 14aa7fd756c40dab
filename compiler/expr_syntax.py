"""Expression text → typed nodes: a hand-written parser of grammar/expr.lark.

The grammar is grammar/expr.lark; this parser gives what lark's LALR parser of it gave, with
the same nodes, offsets and syntax errors (tests/compiler/test_expr_syntax.py compares the two
on generated expressions), without importing lark: lark and its parser tables took 3 MiB of
`mpc lsp`'s memory, which evaluates expressions on every keystroke.

What lark did and this parser does alike:
- tokens are read one at a time, as the parser asks for them: a syntax error is the first
  token that cannot continue the expression (or its end), whatever comes after it;
- a character that starts no token is reported as such (`unexpected '^'`, with a hint);
- a node spans its first to its last token, a parenthesised operand's parentheses included
  (`(1+2)*3` spans 0–7), but a parenthesised expression alone keeps its own span (`1+2`).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from mpc.compiler.expr_nodes import Binary, Call, Name, Node, Num, Unary
from mpc.core.record import record

_CHAR_HINTS = {"^": "use ** for powers", "π": "write pi"}

# The terminals of expr.lark, longest first where one starts another (`**` before `*`).
_TOKEN = re.compile(r"(?P<NUMBER>(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)|(?P<NAME>[A-Za-z_][A-Za-z0-9_]*)"
                    r"|(?P<POW_OP>\*\*)|(?P<MUL_OP>[*/])|(?P<ADD_OP>[+-])|(?P<PUNCT>[(),])")
_SPACE = re.compile(r"[ \t\f\r\n]*")  # common.WS, ignored


class ExprSyntaxError(Exception):
    """offset: where in the text; found: 'unexpected …'; hint: what to write instead, if known."""

    def __init__(self, offset: int, found: str, hint: str | None = None) -> None:
        super().__init__(found)
        self.offset, self.found, self.hint = offset, found, hint


@record
class _Token:
    kind: str  # a terminal's name, the punctuation itself, or "$END"
    text: str
    start: int
    end: int


@record
class _Part:
    """A parsed operand and the span it takes in the expression around it (its parentheses)."""

    node: Node
    start: int
    end: int


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.at = 0
        self.ahead: _Token | None = None

    def peek(self) -> _Token:
        if self.ahead is None:
            self.at = _SPACE.match(self.text, self.at).end()  # type: ignore[union-attr]
            if self.at >= len(self.text):
                self.ahead = _Token("$END", "", self.at, self.at)
            else:
                found = _TOKEN.match(self.text, self.at)
                if found is None:
                    char = self.text[self.at]
                    raise ExprSyntaxError(self.at, f"unexpected '{char}'", _CHAR_HINTS.get(char))
                kind = found.lastgroup or ""
                self.ahead = _Token(found.group() if kind == "PUNCT" else kind, found.group(),
                                    found.start(), found.end())
                self.at = found.end()
        return self.ahead

    def take(self) -> _Token:
        token = self.peek()
        self.ahead = None
        return token

    def expect(self, kind: str) -> _Token:
        if self.peek().kind != kind:
            raise self.unexpected()
        return self.take()

    def unexpected(self) -> ExprSyntaxError:
        token = self.peek()
        if token.kind == "$END":
            return ExprSyntaxError(len(self.text.rstrip()), "unexpected end of expression")
        return ExprSyntaxError(token.start, f"unexpected '{token.text}'")

    # expr: term (ADD_OP term)*; term: factor (MUL_OP factor)*  (left-associative)
    def expr(self) -> _Part:
        return self._left(self.term, "ADD_OP")

    def term(self) -> _Part:
        return self._left(self.factor, "MUL_OP")

    def _left(self, operand: Callable[[], _Part], op_kind: str) -> _Part:
        left = operand()
        while self.peek().kind == op_kind:
            op = self.take()
            left = _binary(left, op, operand())
        return left

    def factor(self) -> _Part:
        """ADD_OP factor | power"""
        if self.peek().kind == "ADD_OP":
            op = self.take()
            operand = self.factor()
            return _Part(Unary(op.text, operand.node, op.start, operand.end), op.start, operand.end)
        return self.power()

    def power(self) -> _Part:
        """atom (POW_OP factor)?: the exponent may carry a sign, the base may not."""
        base = self.atom()
        if self.peek().kind == "POW_OP":
            op = self.take()
            return _binary(base, op, self.factor())
        return base

    def atom(self) -> _Part:
        token = self.peek()
        if token.kind == "NUMBER":
            self.take()
            return _Part(Num(float(token.text), token.start, token.end), token.start, token.end)
        if token.kind == "NAME":
            self.take()
            if self.peek().kind != "(":
                return _Part(Name(token.text, token.start, token.end), token.start, token.end)
            self.take()
            args: list[Node] = []
            if self.peek().kind != ")":
                args.append(self.expr().node)
                while self.peek().kind == ",":
                    self.take()
                    args.append(self.expr().node)
            close = self.expect(")")
            return _Part(Call(token.text, tuple(args), token.start, close.end), token.start, close.end)
        if token.kind == "(":
            self.take()
            inner = self.expr()
            close = self.expect(")")
            return _Part(inner.node, token.start, close.end)
        raise self.unexpected()


def _binary(left: _Part, op: _Token, right: _Part) -> _Part:
    return _Part(Binary(op.text, left.node, right.node, left.start, right.end), left.start, right.end)


def parse_text(text: str) -> Node:
    """The node tree of an expression; raises ExprSyntaxError. Deep nesting raises
    RecursionError (the caller reports too many operators)."""
    parser = _Parser(text)
    node = parser.expr().node
    if parser.peek().kind != "$END":
        raise parser.unexpected()
    return node
