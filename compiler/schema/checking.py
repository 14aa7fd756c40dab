"""A type of the language's schema → the function that checks a value of it and converts it.

The schema's annotations (`list[Expr]`, `bool | None`, `Annotated[…, ONE_OF]`, a node class)
are read once per type into a `Check`: `check(value, walk)` returns the value as the AST holds
it, or raises `Invalid` with every problem found below it, each located by its `loc` (keys
and indices below the value). Scalars convert as YAML users expect and as the language always
has (pydantic's lax mode, which it was declared in before): `yes` is true, `"3"` is 3, 3.0 is 3.

Markers in `Annotated` (compiler/schema/base.py: After, Before, Length, ONE_OF, …) make
their own checks from what they annotate (`check(source, inner)`); a node class makes its
own (`node_check()`), which compiler/schema/base.py's walk runs.
"""

from __future__ import annotations

import functools
import math
import re
import types
import typing
from collections.abc import Callable, Iterator
from typing import Annotated, Any, Literal

Check = Callable[[Any, Any], Any]  # (value, walk) → the value as the AST holds it


class Invalid(Exception):
    """The problems of a value: dicts of `type`, `loc` (below the value), `input`, `msg`, `ctx`."""

    def __init__(self, errors: list[dict[str, Any]]) -> None:
        super().__init__(errors)
        self.errors = errors

    def below(self, step: str | int) -> list[dict[str, Any]]:
        """The problems as seen from the value that holds this one at `step`."""
        return [{**e, "loc": (step, *e["loc"])} for e in self.errors]


def invalid(kind: str, value: Any, msg: str = "", **ctx: Any) -> Invalid:
    """One problem of the value itself."""
    return Invalid([{"type": kind, "loc": (), "input": value, "msg": msg, "ctx": ctx}])


TRUE_WORDS = frozenset({"1", "on", "t", "true", "y", "yes"})  # true or false as text, any case
FALSE_WORDS = frozenset({"0", "off", "f", "false", "n", "no"})


def _any(value: Any, walk: Any) -> Any:
    return value


def _str(value: Any, walk: Any) -> Any:
    if isinstance(value, str):
        return value
    raise invalid("string_type", value)


def _bool(value: Any, walk: Any) -> Any:
    if isinstance(value, bool):
        return value
    if isinstance(value, str):  # "Yes", "off"; not " yes " (YAML strips what it does not quote)
        text = value.lower()
        if text in TRUE_WORDS or text in FALSE_WORDS:
            return text in TRUE_WORDS
        raise invalid("bool_parsing", value)
    if isinstance(value, int | float):
        if value in (0, 1):
            return value == 1
        raise invalid("bool_parsing", value)
    raise invalid("bool_type", value)


_INT_TEXT = re.compile(r"[+-]?[0-9]+(?:_[0-9]+)*(?:\.0+)?")  # an integer as text, as the language reads it


def _int(value: Any, walk: Any) -> Any:
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        if math.isfinite(value) and value.is_integer():
            return int(value)
        raise invalid("int_from_float", value)
    if isinstance(value, str):  # " +3", "1_000", "1.00"; not "1e3", "1.", nor other scripts' digits
        if _INT_TEXT.fullmatch(text := value.strip()):
            return int(text.partition(".")[0])
        raise invalid("int_parsing", value)
    raise invalid("int_type", value)


def _literal(values: tuple[Any, ...]) -> Check:
    expected = _expected(values)
    ints = {v for v in values if isinstance(v, int)}

    def check(value: Any, walk: Any) -> Any:
        for v in values:
            if value == v and type(value) is type(v):
                return v
        if ints and isinstance(value, bool | float):  # True is 1, 1.0 is 1; "1" is no number
            try:
                number = _int(value, walk)
            except Invalid:
                number = None
            if number in ints:
                return number
        raise invalid("literal_error", value, f"Input should be {expected}", expected=expected)
    return check


def _expected(values: tuple[Any, ...]) -> str:
    """pydantic's words for the values of a Literal: "'a', 'b' or 'c'"."""
    words = [repr(v) for v in values]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


def _list(item: Check) -> Check:
    def check(value: Any, walk: Any) -> Any:
        if not isinstance(value, list | tuple | set | frozenset):
            raise invalid("list_type", value)
        out, errors = [], []
        for i, v in enumerate(value):
            try:
                out.append(item(v, walk))
            except Invalid as e:
                errors += e.below(i)
        if errors:
            raise Invalid(errors)
        return out
    return check


def _dict(key: Check, item: Check) -> Check:
    def check(value: Any, walk: Any) -> Any:
        if not isinstance(value, dict):
            raise invalid("dict_type", value)
        out, errors = {}, []
        for k, v in value.items():
            try:
                k2 = key(k, walk)
            except Invalid as e:
                errors += [{**err, "loc": (k, "[key]", *err["loc"])} for err in e.errors]
                k2 = None
            try:
                v2 = item(v, walk)
            except Invalid as e:
                errors += e.below(k)
                continue
            if k2 is not None:
                out[k2] = v2
        if errors:
            raise Invalid(errors)
        return out
    return check


def _nullable(inner: Check) -> Check:
    def check(value: Any, walk: Any) -> Any:
        return None if value is None else inner(value, walk)
    return check


def _made_or_new(made: Check | None, tp: Any, names: dict[str, Any] | None) -> Check:
    return made if made is not None else checker(tp, names)


_LEAVES: dict[Any, Check] = {Any: _any, str: _str, bool: _bool, int: _int}


def resolved(tp: Any, names: dict[str, Any] | None) -> Any:
    """The type an annotation names, a quoted one (`list["AssembleChild"]`) looked up in
    `names`, the module it was written in."""
    if isinstance(tp, str | typing.ForwardRef):
        return eval(tp if isinstance(tp, str) else tp.__forward_arg__, names)  # the schema's own text
    return tp


def wrapping(source: Any, markers: list[Any]) -> Iterator[tuple[Any, Any]]:
    """Each marker of `Annotated[source, *markers]` with what it wraps: the type left of it."""
    for i, marker in enumerate(markers):
        yield (Annotated[(source, *markers[:i])] if i else source), marker


def checker(tp: Any, names: dict[str, Any] | None = None) -> Check:
    """The check of values of the type `tp`; `names`: the module its annotations were
    written in (for the names they quote)."""
    tp = resolved(tp, names)
    origin = typing.get_origin(tp)
    if origin is Annotated:
        source, *markers = typing.get_args(tp)
        check: Check | None = None
        for below, marker in wrapping(source, markers):
            if hasattr(marker, "check"):
                check = marker.check(below, functools.partial(_made_or_new, check, below, names))
        return check if check is not None else checker(source, names)
    if origin in (typing.Union, types.UnionType):
        members = [m for m in typing.get_args(tp) if m is not type(None)]
        if len(members) == 1 and len(members) < len(typing.get_args(tp)):
            return _nullable(checker(members[0], names))
        raise TypeError(f"a union without ONE_OF or BY_TYPE: {tp}")
    if origin is Literal:
        return _literal(typing.get_args(tp))
    if origin is list:
        return _list(checker(typing.get_args(tp)[0], names))
    if origin is dict:
        key, value = typing.get_args(tp)
        return _dict(checker(key, names), checker(value, names))
    if tp in _LEAVES:
        return _LEAVES[tp]
    node_check = getattr(tp, "node_check", None)
    if node_check is not None:
        return typing.cast(Check, node_check())
    raise TypeError(f"the schema has no check for {tp!r}")
