"""How much a xacro expansion may compute: bounded, so that a hostile model cannot hang mpc.

xacro's expressions are Python, and Python computes without bound: `${9**9**9}` is one
multiplication of integers that runs for hours, `${'a' * 10**12}` one allocation of a
terabyte, and a macro that calls itself twice per level expands 2⁴⁰ times. Two guards:

- **Each operation** (`bounded_code`): the operators and functions that make a value far
  larger than their operands in one step of C code, where nothing can interrupt them, are
  checked before they run: `**`, `*` and `<<` of integers beyond `MAX_BITS` bits, a string,
  list or tuple repeated beyond `MAX_ITEMS` items, `%` formatting and f-string format specs
  wider than `MAX_WIDTH`, `range` beyond `MAX_ITEMS`, and `math.factorial`, `comb`, `perm`
  and `prod` beyond `MAX_BITS`. An expression that asks for more is refused (E0673).
- **The whole expansion** (`watched`): a watchdog ends it when it has run `MAX_SECONDS`, or
  when the process has grown by `MAX_MEMORY` bytes since it started (E0673). It raises in
  the expanding thread between two steps of Python code: macros, loops and comprehensions,
  whose single steps the first guard keeps small. No `except Exception` catches it, and it is
  raised again until the expansion has ended.
The limits are far above what a robot model computes (the largest xacro models of ROS
packages expand in about a second and never need a megabit integer).
"""

from __future__ import annotations

import ast
import contextlib
import ctypes
import functools
import math
import operator
import os
import re
import threading
import time
from collections.abc import Callable, Iterator
from types import CodeType
from typing import Any

MAX_BITS = 1_000_000  # an integer of about 300,000 digits
MAX_ITEMS = 10_000_000  # characters of a string, items of a list, tuple or range
MAX_WIDTH = 10_000  # a field's width or precision in a format
MAX_SECONDS = 60.0
MAX_MEMORY = 2 << 30  # bytes the process may grow by while one expansion runs
_POLL = 0.05
# After raising, how long the watchdog waits for the block to end before raising again: an
# exception raised while a destructor or a weakref callback runs is printed and dropped.
_AGAIN = 0.5
BOUNDED = "__mpc_bounded"  # the name the transformed code calls (a user's `__` names are refused)


class TooLarge(Exception):
    """An expression asked for more than a limit; the message says what."""


class ExpansionTooLong(BaseException):
    """Raised in the expanding thread by the watchdog (`watched`); `reason` says which limit.

    A BaseException, as KeyboardInterrupt is: xacro reads a literal by trying int, float and
    bool in turn under `except Exception: pass`, so an Exception raised there was swallowed and
    the expansion ran on (a model of 2²² macro calls, stopped at 1 s, still ran 17 minutes
    later, at 1.9 GB)."""

    reason = ""


def _bits(value: int) -> int:
    return abs(value).bit_length()


def _repeat(seq: Any, times: Any) -> None:
    sequence = isinstance(seq, str | bytes | list | tuple)
    if sequence and isinstance(times, int) and len(seq) * times > MAX_ITEMS:
        raise TooLarge(f"it makes a sequence of {len(seq) * times:,} items (more than {MAX_ITEMS:,})")


def _power(base: Any, exponent: Any) -> None:
    if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1 \
            and exponent * math.log2(abs(base)) > MAX_BITS:
        raise TooLarge(f"its power has more than {MAX_BITS:,} bits")


def _product(a: Any, b: Any) -> None:
    if isinstance(a, int) and isinstance(b, int) and _bits(a) + _bits(b) > MAX_BITS:
        raise TooLarge(f"its product has more than {MAX_BITS:,} bits")
    _repeat(a, b)
    _repeat(b, a)


def _shift(a: Any, b: Any) -> None:
    if isinstance(a, int) and isinstance(b, int) and a and _bits(a) + b > MAX_BITS:
        raise TooLarge(f"its shift has more than {MAX_BITS:,} bits")


_WIDTHS = re.compile(r"\d+")
_PERCENT_FIELD = re.compile(r"%[-#0 +]*(\*|\d+)?(?:\.(\*|\d+))?")


def _percent(text: Any, args: Any) -> None:
    if not isinstance(text, str | bytes):
        return
    fields = _PERCENT_FIELD.findall(text if isinstance(text, str) else text.decode("latin-1"))
    for width, precision in fields:
        for part in (width, precision):
            if part == "*":
                raise TooLarge("its format takes a width from its arguments (`*`)")
            if part and int(part) > MAX_WIDTH:
                raise TooLarge(f"its format is wider than {MAX_WIDTH:,} characters")


_CHECKS: dict[str, Callable[[Any, Any], None]] = {
    "**": _power, "*": _product, "<<": _shift, "%": _percent}
_OPERATORS: dict[str, Callable[[Any, Any], Any]] = {
    "**": operator.pow, "*": operator.mul, "<<": operator.lshift, "%": operator.mod}
_AST_OPERATORS: dict[type, str] = {ast.Pow: "**", ast.Mult: "*", ast.LShift: "<<", ast.Mod: "%"}


def _bounded(op: str, a: Any, b: Any) -> Any:
    _CHECKS[op](a, b)
    return _OPERATORS[op](a, b)


class _Bound(ast.NodeTransformer):
    """`a ** b`, `a * b`, `a << b` and `a % b` → `__mpc_bounded(op, a, b)`; a format spec
    that is wider than MAX_WIDTH or computed is refused."""

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        op = _AST_OPERATORS.get(type(node.op))
        if op is None:
            return node
        call = ast.Call(ast.Name(BOUNDED, ast.Load()), [ast.Constant(op), node.left, node.right], [])
        return ast.copy_location(call, node)

    def visit_FormattedValue(self, node: ast.FormattedValue) -> ast.AST:
        self.generic_visit(node)
        spec = node.format_spec
        if spec is not None:
            parts = spec.values if isinstance(spec, ast.JoinedStr) else [spec]
            for part in parts:
                if not (isinstance(part, ast.Constant) and isinstance(part.value, str)):
                    raise TooLarge("its format spec is computed")
                if any(int(w) > MAX_WIDTH for w in _WIDTHS.findall(part.value)):
                    raise TooLarge(f"its format is wider than {MAX_WIDTH:,} characters")
        return node


@functools.lru_cache(maxsize=8192)
def bounded_code(expression: str) -> CodeType | str:
    """The code of `expression` with its operations bounded, or why it is refused (TooLarge's
    message). A text that is no expression is compiled as it is, for Python to say why."""
    try:
        tree = ast.parse(expression.strip(), mode="eval")
    except (SyntaxError, ValueError):
        return compile(expression.strip(), "<expression>", "eval")
    try:
        tree = ast.fix_missing_locations(_Bound().visit(tree))
    except TooLarge as e:
        return str(e)
    return compile(tree, "<expression>", "eval")


def builtins_of(given: dict[str, Any]) -> dict[str, Any]:
    """The builtins an expression is evaluated with: `given` and the bounded operations."""
    return {**given, BOUNDED: _bounded}


def _bounded_range(*args: int) -> range:
    made = range(*args)
    if len(made) > MAX_ITEMS:
        raise TooLarge(f"its range has {len(made):,} items (more than {MAX_ITEMS:,})")
    return made


def _bounded_factorial(n: int) -> int:
    if isinstance(n, int) and n > 0 and n * math.log2(max(n, 2)) > MAX_BITS:
        raise TooLarge(f"factorial({n}) has more than {MAX_BITS:,} bits")
    return math.factorial(n)


def _bounded_comb(n: int, k: int) -> int:
    if isinstance(n, int) and isinstance(k, int) and min(k, n - k) * math.log2(max(n, 2)) > MAX_BITS:
        raise TooLarge(f"comb({n}, {k}) has more than {MAX_BITS:,} bits")
    return math.comb(n, k)


def _bounded_perm(n: int, k: int | None = None) -> int:
    if isinstance(n, int) and (k if isinstance(k, int) else n) * math.log2(max(n, 2)) > MAX_BITS:
        raise TooLarge(f"perm({n}, {k}) has more than {MAX_BITS:,} bits")
    return math.perm(n, k)


def _bounded_prod(iterable: Any, *, start: Any = 1) -> Any:
    return functools.reduce(lambda a, b: _bounded("*", a, b), iterable, start)


# What replaces xacro's own symbols of these names (`range`, `python.range`, `math.factorial`,
# and `factorial` …: xacro exposes math's functions both ways).
BOUNDED_SYMBOLS: dict[str, Callable[..., Any]] = {
    "range": _bounded_range, "factorial": _bounded_factorial, "comb": _bounded_comb,
    "perm": _bounded_perm, "prod": _bounded_prod}


def bound_symbols(symbols: dict[str, Any]) -> None:
    """Replace, in xacro's symbol table, the functions of `BOUNDED_SYMBOLS` wherever they stand."""
    for table in (symbols, symbols.get("python"), symbols.get("math")):
        if isinstance(table, dict):
            for name in BOUNDED_SYMBOLS.keys() & table.keys():
                table[name] = BOUNDED_SYMBOLS[name]


def _resident_bytes() -> int:
    try:
        with open("/proc/self/statm", "rb") as statm:
            return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


@contextlib.contextmanager
def watched() -> Iterator[None]:
    """Run the block (one expansion) under the watchdog: past MAX_SECONDS, or MAX_MEMORY more
    resident memory than at its start, ExpansionTooLong is raised in this thread, and raised
    again each `_AGAIN` seconds until the block is left."""
    target = threading.get_ident()
    lock = threading.Lock()
    done = threading.Event()
    fired: list[str] = []
    start, base = time.monotonic(), _resident_bytes()

    def watch() -> None:
        while not done.wait(_POLL):
            elapsed, grown = time.monotonic() - start, _resident_bytes() - base
            why = fired[0] if fired else (
                f"it ran for more than {MAX_SECONDS:g} s" if elapsed > MAX_SECONDS else
                f"it took more than {MAX_MEMORY >> 20:,} MiB of memory" if grown > MAX_MEMORY else "")
            if why:
                with lock:
                    if done.is_set():
                        return
                    ExpansionTooLong.reason = why
                    fired.append(why)
                    ctypes.pythonapi.PyThreadState_SetAsyncExc(
                        ctypes.c_ulong(target), ctypes.py_object(ExpansionTooLong))
                done.wait(_AGAIN)  # and again, until the block is left

    watcher = threading.Thread(target=watch, name="mpc-xacro-watchdog", daemon=True)
    watcher.start()
    try:
        yield
    finally:
        with lock:
            done.set()
            if fired:  # raised already, or still pending: it must not reach the code after
                ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(target), None)
        watcher.join()
