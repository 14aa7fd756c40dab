"""A number written in a definition (int, float, `"-pi/2"`, `[deg, 90]`) → float, or a diagnostic.

Parses by grammar/expr.lark (compiler/expr_syntax.py) and evaluates with the math module;
never Python `eval`. It knows only `pi` and the functions in FUNCTIONS: no variables, no user functions.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from functools import lru_cache

from mpc.compiler.expr_nodes import Binary, Call, Name, Node, Num, Unary
from mpc.compiler.expr_syntax import ExprSyntaxError, parse_text
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.record import record
from mpc.core.span import Span, source_line

CONSTANTS: dict[str, float] = {"pi": math.pi}
UNITS: dict[str, Callable[[float], float]] = {"deg": math.radians, "rad": float}
# name → (fewest arguments, most arguments or None for no limit, implementation)
FUNCTIONS: dict[str, tuple[int, int | None, Callable[..., float]]] = {
    "deg": (1, 1, math.radians), "rad": (1, 1, float), "sqrt": (1, 1, math.sqrt),
    "sin": (1, 1, math.sin), "cos": (1, 1, math.cos), "tan": (1, 1, math.tan),
    "asin": (1, 1, math.asin), "acos": (1, 1, math.acos), "atan": (1, 1, math.atan),
    "atan2": (2, 2, math.atan2), "abs": (1, 1, math.fabs), "min": (2, None, min), "max": (2, None, max),
}


@lru_cache(maxsize=4096)
def parse(text: str) -> Node:
    """Expression text → node tree; raises ExprSyntaxError on a syntax error. Kept per text: a
    definition repeats its expressions, and `mpc lsp` parses it on every keystroke."""
    return parse_text(text)


def evaluate(value: object, span: Span, sink: Sink, *, what: str = "value") -> float | None:
    """A number written in a definition → float, or None after reporting a diagnostic."""
    if isinstance(value, list):
        return _pair(value, span, sink, what)
    if isinstance(value, str):
        return _expression(value, _Where(span, value, last=False), sink, what)
    if isinstance(value, bool) or not isinstance(value, int | float):
        sink.error(span, "E0214", f"{what} must be a number, got {_describe(value)}")
        return None
    try:
        result = float(value)
    except OverflowError:  # an int beyond the float range
        result = math.inf
    if not math.isfinite(result):
        sink.error(span, "E0213", f"{what} must be a finite number, got {result}")
        return None
    return result


def _pair(value: list[object], span: Span, sink: Sink, what: str) -> float | None:
    """`[unit, number]`, e.g. `[deg, 90]`."""
    if len(value) != 2:
        sink.error(span, "E0214", f"{what} must be a number or a [unit, value] pair like [deg, 90], "
                                  f"got a list of {len(value)} items")
        return None
    unit, number = value
    if not isinstance(unit, str) or unit not in UNITS:
        near = did_you_mean(unit, set(UNITS)) if isinstance(unit, str) else ""
        sink.error(span, "E0214", f"unknown unit '{unit}' for {what}{near}", hint="units are deg and rad")
        return None
    if isinstance(number, str):
        result = _expression(number, _Where(span, number, last=True), sink, what)
    elif isinstance(number, list | dict):
        sink.error(span, "E0214", f"the value in [{unit}, …] for {what} must be a number, "
                                  f"got {_describe(number)}")
        return None
    else:
        result = evaluate(number, span, sink, what=what)
    return None if result is None else UNITS[unit](result)


def _describe(value: object) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    return {type(None): "null", dict: "a mapping", list: "a list"}.get(type(value), type(value).__name__)


class _Where:
    """Maps offsets in an expression's text onto the file: `at`. Where the text starts on its
    line is looked up in the file when a diagnostic first asks (most expressions report
    nothing, and `mpc lsp` evaluates every one of a definition on each keystroke)."""

    __slots__ = ("_col", "_last", "_text", "span")
    _UNKNOWN = object()

    def __init__(self, span: Span, text: str, *, last: bool) -> None:
        """`text`: the whole scalar, or (last) the last item of a flow list."""
        self.span, self._text, self._last, self._col = span, text, last, _Where._UNKNOWN

    @property
    def col(self) -> int | None:
        """The column where the text starts, if known."""
        if self._col is _Where._UNKNOWN:
            self._col = self._find()
        return self._col  # type: ignore[return-value]

    def _find(self) -> int | None:
        """Find the text in the source line."""
        span, text, last = self.span, self._text, self._last
        if "\n" in text or span.end_line > span.line:
            return None  # block and folded scalars: offsets are not columns
        line = source_line(span.file, span.line)
        if line is None:
            return None if last else span.col  # unreadable: assume unquoted
        if last:
            stop = span.end_col - 1 if span.end_col > span.col else len(line)
            i = line.rfind(text, span.col - 1, stop)
            return i + 1 if i >= 0 else None
        col = span.col + (line[span.col - 1:span.col] in ("'", '"'))
        # An escape sequence in a double-quoted scalar breaks the mapping; fall back to the start.
        return col if line[col - 1:col - 1 + len(text)] == text else None

    def at(self, start: int, end: int) -> Span:
        col = self.col
        if col is None:
            return self.span
        return Span(self.span.file, self.span.line, col + start, self.span.line, col + end)


def _expression(text: str, where: _Where, sink: Sink, what: str) -> float | None:
    shown = " ".join(text.split()) if "\n" in text else text
    if not text.strip():
        sink.error(where.span, "E0210", f"empty expression for {what}")
        return None
    try:
        node = parse(text)
        result = _Evaluator(shown, where, sink, what).value(node)
    except ExprSyntaxError as e:
        sink.error(where.at(e.offset, e.offset + 1), "E0210", f"invalid expression '{shown}' for {what}: "
                   f"{e.found}", hint=e.hint)
        return None
    except RecursionError:  # both the transformer and the evaluator recurse once per operator
        sink.error(where.span, "E0210", f"the expression for {what} has too many operators")
        return None
    if result is not None and not math.isfinite(result):
        sink.error(where.at(node.start, node.end), "E0213",
                   f"cannot evaluate '{shown}' for {what}: the result is not finite")
        return None
    return result


@record(frozen=False)
class _Evaluator:
    """Computes a node tree; reports every bad name and call in it, not only the first."""

    text: str
    where: _Where
    sink: Sink
    what: str

    def value(self, node: Node) -> float | None:
        match node:
            case Num(value=v):
                return v
            case Name(id=name) if name in CONSTANTS:
                return CONSTANTS[name]
            case Name(id=name):
                hint = f"'{name}' is a function: write {name}(…)" if name in FUNCTIONS else None
                self.sink.error(self.where.at(node.start, node.end), "E0211",
                                f"unknown name '{name}' in expression for {self.what}"
                                f"{did_you_mean(name, set(CONSTANTS))}", hint=hint)
                return None
            case Unary(op=op, operand=operand):
                v = self.value(operand)
                return None if v is None else (-v if op == "-" else v)
            case Binary(op=op, left=left, right=right):
                a, b = self.value(left), self.value(right)
                if a is None or b is None:
                    return None
                return self.compute(node, _BINARY[op], a, b, undefined=f"{_g(a)} {op} {_g(b)} is undefined")
            case Call(func=func, args=args):
                return self.call(node, func, args)

    def call(self, node: Call, func: str, args: tuple[Node, ...]) -> float | None:
        if func not in FUNCTIONS:
            self.sink.error(self.where.at(node.start, node.end), "E0212",
                            f"unknown function '{func}' in expression for {self.what}"
                            f"{did_you_mean(func, set(FUNCTIONS))}",
                            hint=f"functions are {', '.join(FUNCTIONS)}")
            return None
        fewest, most, fn = FUNCTIONS[func]
        if len(args) < fewest or (most is not None and len(args) > most):
            want = f"{'at least ' if most is None else ''}{fewest} argument{'s' if fewest > 1 else ''}"
            self.sink.error(self.where.at(node.start, node.end), "E0212",
                            f"function '{func}' takes {want} but got {len(args)} "
                            f"in expression for {self.what}")
            return None
        values = [v for v in [self.value(a) for a in args] if v is not None]
        if len(values) < len(args):
            return None
        shown = ", ".join(f"{v:g}" for v in values)
        return self.compute(node, fn, *values, undefined=f"{func}({shown}) is undefined")

    def compute(self, node: Node, fn: Callable[..., float], *args: float, undefined: str) -> float | None:
        try:
            return float(fn(*args))
        except ZeroDivisionError:
            reason = "division by zero" if isinstance(node, Binary) and node.op == "/" else undefined
        except OverflowError:
            reason = "the result is too large"
        except ValueError:
            reason = undefined
        self.sink.error(self.where.at(node.start, node.end), "E0213",
                        f"cannot evaluate '{self.text}' for {self.what}: {reason}")
        return None


def _g(v: float) -> str:
    return f"({v:g})" if v < 0 else f"{v:g}"


_BINARY: dict[str, Callable[[float, float], float]] = {
    "+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv,
    "**": math.pow,  # not operator.pow: (-8.0) ** (1/3) would be a complex number
}
