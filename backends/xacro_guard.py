"""What a xacro model may do while it expands: compute, not run code; read, within the rule.

xacro evaluates `${…}` and `$(eval …)` with Python's `eval`. Its own guard refuses names that
start with `__` only at an expression's top level (not in a comprehension or a lambda), lets
`str.format` walk attributes (`"{0.__class__}".format(x)`) and gives `$(eval …)` all of
Python's builtins (`open`, `exec`). During an expansion (`guarded`) every expression is
first parsed and refused, wherever in it they appear, when it holds

- a name that starts with `__`, or an attribute that starts with `_`;
- an attribute that walks to Python's internals without an underscore (`format`,
  `format_map`, `mro`, the frames and code of generators and coroutines);

and the symbols it sees lose `python.vars` and `python.type` (a class's dictionary, and
through it every class of the process). `$(eval …)` gets the builtins xacro's `${…}` has,
not all of Python's. `$(env NAME)` and `$(optenv NAME)` read only the variables the input
model lists in `xacro_env`. Every file xacro opens (an include, `xacro.load_yaml`) must pass
the read rule of every input (core/packages.py `refusal`). A refusal raises `Refused`, which
the reader turns into a diagnostic; nothing of the refused expression is evaluated.
What an expansion may compute is bounded too (backends/xacro_limits.py, E0673): each
operation that could run without end in one step, and the whole expansion's time and memory.
"""

from __future__ import annotations

import ast
import builtins
import contextlib
import functools
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from mpc.backends.xacro_limits import ExpansionTooLong, TooLarge, bound_symbols, bounded_code, builtins_of
from mpc.core.packages import PackageResolver
from mpc.core.reads import note_volatile

# Attributes without an underscore that lead to Python's internals: the mini-language of
# str.format walks attributes (`{0.__globals__}`); a class's method resolution order names
# `object`; a generator's, coroutine's or frame's attributes reach the globals of any module.
DENIED_ATTRIBUTES = frozenset({
    "format", "format_map", "mro",
    "gi_frame", "gi_code", "gi_yieldfrom", "gi_suspended",
    "cr_frame", "cr_code", "cr_await", "cr_origin",
    "ag_frame", "ag_code", "ag_await",
    "f_globals", "f_locals", "f_builtins", "f_back", "f_code", "f_trace",
    "tb_frame", "tb_next",
})
# The symbols of xacro's `python` namespace an expression does not get.
DENIED_SYMBOLS = ("vars", "type")
# The builtins of `$(eval …)`: those xacro's `${…}` offers by name.
EVAL_BUILTINS = {name: getattr(builtins, name) for name in (
    "list", "dict", "map", "len", "str", "float", "int", "bool", "min", "max", "round", "abs",
    "all", "any", "sorted", "range", "sum", "zip", "enumerate", "tuple", "set", "repr")}


class Refused(Exception):
    """What a xacro model may not do: `code` and `message` become its diagnostic; `needle`
    is the text to find its line by in the file being expanded."""

    def __init__(self, code: str, message: str, needle: str) -> None:
        super().__init__(message)
        self.code, self.message, self.needle = code, message, needle


@functools.lru_cache(maxsize=8192)
def expression_problem(expression: str) -> str | None:
    """Why the Python expression of a `${…}` or `$(eval …)` is refused, or None (also when it
    is no valid expression: xacro reports that in its own words)."""
    try:
        tree = ast.parse(expression.strip(), mode="eval")
    except (SyntaxError, ValueError):
        return None
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id.startswith("__"):
            return f"it uses the name '{node.id}'"
        if isinstance(node, ast.Attribute) and (node.attr.startswith("_") or node.attr in DENIED_ATTRIBUTES):
            return f"it reads the attribute '{node.attr}', which leads to Python's internals"
    return None


def check_expression(expression: str) -> None:
    """Raise `Refused` (E0670) when `expression` is refused."""
    why = expression_problem(expression)
    if why is not None:
        raise Refused("E0670", f"the expression '{_short(expression)}' is not evaluated: {why} "
                      "(a xacro model computes values; it does not reach into Python)", expression)


def evaluate(expression: str, globals: Any, locals: Any) -> Any:
    """`expression` evaluated as xacro evaluates it, once it is allowed (`check_expression`) and
    with its operations bounded (backends/xacro_limits.py); past a bound, `Refused` (E0673)."""
    check_expression(expression)
    code = bounded_code(expression)
    try:
        if isinstance(code, str):
            raise TooLarge(code)
        return builtins.eval(code, globals, locals)
    except TooLarge as e:
        raise Refused("E0673", f"the expression '{_short(expression)}' is not evaluated: {e} (a xacro "
                      "model computes values of the size a robot needs)", expression) from None


def _short(text: str) -> str:
    text = " ".join(text.split())
    return text if len(text) <= 80 else text[:77] + "..."


@contextlib.contextmanager
def guarded(resolver: PackageResolver, near: Path, environment: tuple[str, ...]) -> Iterator[None]:
    """xacro, for one expansion, under the rules of the module docstring. near: the folder
    of the xacro file being expanded, whose files it may include besides the project's and
    the packages'. environment: the variables `$(env)` and `$(optenv)` may read."""
    import xacro
    from xacro import substitution_args as subst

    def safe_eval(expression: str, globals: Any, locals: Any = None) -> Any:
        # xacro's own safe_eval, less its builtins and with the operations bounded
        globals.update(__builtins__=builtins_of({}))
        return evaluate(expression, globals, locals)

    def restricted_eval(expression: str, _globals: Any = None, locals: Any = None) -> Any:
        return evaluate(expression, {"__builtins__": builtins_of(EVAL_BUILTINS)}, locals)

    def allowed(name: str) -> None:
        if name not in environment:
            raise Refused("E0671", f"$(env {name}) / $(optenv {name}): the environment variable "
                          f"'{name}' is not read; the input model lists the variables its xacro "
                          "may read in `xacro_env`", name)
        note_volatile(f"a xacro model reads the environment variable {name}")

    def env(name: str) -> str:
        allowed(name)
        return original_env(name)

    def optenv(name: str, default: str = "") -> str:
        allowed(name)
        return os.environ.get(name, default)

    def checked_file(found: Callable[[str], Any]) -> Callable[[str], Any]:
        def check(spec: str) -> Any:
            path = found(spec)
            if why := resolver.refusal(Path(path), near):
                raise Refused("E0650", f"'{spec}', included or loaded by a xacro model, is not read: "
                              f"{why}", spec)
            return path
        return check

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:  # an include (a glob's files each)
            try:
                checked_file(lambda spec: spec)(filename)
            except Refused:
                if xacro.filestack and xacro.filestack[-1] == filename:
                    xacro.filestack.pop()  # as xacro's parse does for a file it cannot open
                raise
        return original_parse(inp, filename)

    symbols = xacro.create_global_symbols()  # a fresh table: no expansion sees another's edits
    for name in DENIED_SYMBOLS:
        symbols["python"].pop(name, None)
    bound_symbols(symbols)
    original_env, original_parse = subst._eval_env, xacro.parse
    saved = (xacro._global_symbols, xacro.safe_eval, xacro.parse, xacro.abs_filename_spec,
             subst._eval_env, subst._eval_optenv, dict(subst._eval_dict), subst.__dict__.get("eval"))
    xacro._global_symbols, xacro.safe_eval, xacro.parse = symbols, safe_eval, parse
    xacro.abs_filename_spec = checked_file(xacro.abs_filename_spec)
    subst._eval_env, subst._eval_optenv = env, optenv
    subst._eval_dict.update(env=env, optenv=optenv)
    subst.eval = restricted_eval  # type: ignore[attr-defined]  # what `$(eval …)` calls
    try:
        yield
    finally:
        (xacro._global_symbols, xacro.safe_eval, xacro.parse, xacro.abs_filename_spec,
         subst._eval_env, subst._eval_optenv, eval_dict, own_eval) = saved
        subst._eval_dict.clear()
        subst._eval_dict.update(eval_dict)
        if own_eval is None:
            del subst.eval  # type: ignore[attr-defined]
        else:
            subst.eval = own_eval  # type: ignore[attr-defined]


def refusal_of(error: BaseException) -> Refused | None:
    """The `Refused` that `error` is, or wraps (xacro wraps what an expression raised)."""
    seen: BaseException | None = error
    while seen is not None:
        if isinstance(seen, Refused):
            return seen
        if isinstance(seen, ExpansionTooLong):
            return Refused("E0673", f"the expansion was stopped: {ExpansionTooLong.reason} (a xacro model "
                           "computes values of the size a robot needs)", "")
        seen = getattr(seen, "exc", None) or seen.__cause__ or seen.__context__
    return None
