"""`@record`: a frozen dataclass whose repr, == and hash are written once, here.

`@dataclass` compiles each method it generates with exec() when the class is created:
six for a frozen class, 0.5–0.8 ms a class on our machines. The IR has over a hundred
classes, and `mpc check` imports most of them on every editor save (issue 3: 250 ms
cold). A record lets dataclass generate only `__init__` and the frozen `__setattr__`
and `__delattr__`; the three methods below behave as dataclass's own would (fields in
order, the class's qualified name, equal only to the same class, tuple hash), so
`dataclasses.fields`, `replace` and `asdict` and every repr-based digest are unchanged.
A record with slots also pickles its fields as a tuple, in order, as dataclass's own
`__getstate__` does, without looking the fields up for each object.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from operator import attrgetter
from typing import Any, TypeVar, dataclass_transform, overload

T = TypeVar("T", bound=type)

_VALUES: dict[type, Callable[[Any], tuple[Any, ...]]] = {}


def _values(obj: Any) -> tuple[Any, ...]:
    cls = type(obj)
    get = _VALUES.get(cls)
    if get is None:
        names = [f.name for f in fields(obj)]
        get = attrgetter(*names) if len(names) > 1 else (
            (lambda o, n=names[0]: (getattr(o, n),)) if names else (lambda o: ()))
        _VALUES[cls] = get
    return get(obj)


def _repr(self: Any) -> str:
    items = ", ".join(f"{f.name}={getattr(self, f.name)!r}" for f in fields(self) if f.repr)
    return f"{type(self).__qualname__}({items})"


def _eq(self: Any, other: object) -> bool:
    if other.__class__ is not self.__class__:
        return NotImplemented
    return _values(self) == _values(other)


def _hash(self: Any) -> int:
    return hash(_values(self))


_NAMES: dict[type, tuple[str, ...]] = {}


def _getstate(self: Any) -> tuple[Any, ...]:
    return _values(self)


def _setstate(self: Any, state: tuple[Any, ...]) -> None:
    cls = type(self)
    names = _NAMES.get(cls)
    if names is None:
        names = _NAMES[cls] = tuple(f.name for f in fields(self))
    for name, value in zip(names, state, strict=True):
        object.__setattr__(self, name, value)


@overload
def record(cls: T, /) -> T: ...
@overload
def record(*, slots: bool = False, kw_only: bool = False) -> Callable[[T], T]: ...


@dataclass_transform(frozen_default=True)
def record(cls: Any = None, /, *, slots: bool = False, kw_only: bool = False) -> Any:
    """`@dataclass(frozen=True, …)` with repr, == and hash from this module."""

    def wrap(c: T) -> T:
        out = dataclass(c, frozen=True, repr=False, eq=False, slots=slots, kw_only=kw_only)
        methods = [("__repr__", _repr), ("__eq__", _eq), ("__hash__", _hash)]
        if slots:  # dataclass's own look each field up anew for every object pickled (build cache)
            methods += [("__getstate__", _getstate), ("__setstate__", _setstate)]
        for name, method in methods:
            if name not in c.__dict__:
                setattr(out, name, method)
        return out

    return wrap if cls is None else wrap(cls)
