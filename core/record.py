"""`@record`: a frozen dataclass whose repr, == and hash are written once, here.

`@dataclass` compiles each method it generates with exec() when the class is created:
six for a frozen class, 0.5–0.8 ms a class on our machines. The IR has over a hundred
classes, and `mpc check` imports most of them on every editor save (issue 3: 250 ms
cold). A record lets dataclass generate only `__init__` and the frozen `__setattr__`
and `__delattr__`; the three methods below behave as dataclass's own would (fields in
order, the class's qualified name, equal only to the same class, tuple hash), so
`dataclasses.fields`, `replace` and `asdict` and every repr-based digest are unchanged.

Two things read dataclass's internals (the parameters and defaults of the `__init__` it
generates), for the classes a reader makes by the thousand, and only for those: the classes
that opt in with `@record(slots=True, bulk=True)` (`bulk_records()`: the URDF reader's IR
values and Span). Such a class gets, when it is first made, an `__init__` that sets each slot
through the slot's own setter (`_fast_init`): dataclass's frozen one goes through
object.__setattr__ for every field, which takes twice as long. And code that makes thousands
of them (a reader) asks for a `maker`, which skips the class call too: a quarter of its time.
Every other record keeps dataclass's own `__init__`, and `maker` refuses it. Where the
internals are not as expected (another Python), both fall back to dataclass's `__init__`;
tests/core/test_record.py fails then, on each supported Python it runs on. A record with
slots also pickles its fields as a tuple, in order, as dataclass's own `__getstate__` does,
without looking the fields up for each object. The build cache writes records as their field
values (`record_values`) and reads them back without running their code (`from_values`:
compiler/kept_values.py); only classes made here (`is_record`) are read back.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from dataclasses import MISSING, dataclass, fields
from operator import attrgetter
from typing import Any, TypeVar, dataclass_transform, overload

T = TypeVar("T", bound=type)
R = TypeVar("R")

_NAMES: dict[type, tuple[str, ...]] = {}
_VALUES: dict[type, Callable[[Any], tuple[Any, ...]]] = {}
_RECORDS: set[type] = set()  # every class made by @record
_BULK: set[type] = set()  # those made in bulk: @record(slots=True, bulk=True)


def _names(cls: type) -> tuple[str, ...]:
    """The record's field names, in order (looked up once per class)."""
    names = _NAMES.get(cls)
    if names is None:
        names = _NAMES[cls] = tuple(f.name for f in fields(cls))  # type: ignore[arg-type]
    return names


def _values(obj: Any) -> tuple[Any, ...]:
    """The record's field values, in order; also what it pickles (`__getstate__`)."""
    cls = type(obj)
    get = _VALUES.get(cls)
    if get is None:
        names = _names(cls)
        get = attrgetter(*names) if len(names) > 1 else (
            (lambda o, n=names[0]: (getattr(o, n),)) if names else (lambda o: ()))
        _VALUES[cls] = get
    return get(obj)


def is_record(cls: type) -> bool:
    """Whether `cls` was made by @record (not a subclass of one that was not)."""
    return cls in _RECORDS


def bulk_records() -> frozenset[type]:
    """The record classes that opted in to `maker` and the fast `__init__` (bulk=True)."""
    return frozenset(_BULK)


def record_fields(cls: type) -> tuple[str, ...]:
    """A record class's field names, in order."""
    return _names(cls)


def record_values(obj: Any) -> tuple[Any, ...]:
    """A record's field values, in the order of `record_fields`."""
    return _values(obj)


def from_values(cls: type[R], values: list[Any]) -> R:
    """The record `cls` with these field values, set as unpickling sets them: neither
    `__init__` nor `__post_init__` runs. Raises ValueError when there is not one value per
    field."""
    build = _BUILDERS.get(cls)
    if build is None:
        build = _BUILDERS[cls] = _builder(cls)
    return build(values)  # type: ignore[no-any-return]


_BUILDERS: dict[type, Callable[[list[Any]], Any]] = {}


def _builder(cls: type) -> Callable[[list[Any]], Any]:
    """`from_values` of `cls`: for a record with slots, a function that sets each slot through
    its own setter (the build cache reads thousands of records; a loop of object.__setattr__
    takes three times as long)."""
    names = _names(cls)
    setters = [getattr(cls, name, None) for name in names]
    if not all(isinstance(s, types.MemberDescriptorType) for s in setters):
        def build(values: list[Any]) -> Any:
            obj = object.__new__(cls)
            _setstate(obj, tuple(values))
            return obj
        return build
    env: dict[str, Any] = {"_new": object.__new__, "_cls": cls, "_n": len(names)}
    lines = ["def build(v):\n", "    if len(v) != _n:\n",
             "        raise ValueError(f'{len(v)} values for {_n} fields')\n", "    o = _new(_cls)\n"]
    for i, setter in enumerate(setters):
        env[f"_s{i}"] = setter.__set__  # type: ignore[union-attr]
        lines.append(f"    _s{i}(o, v[{i}])\n")
    lines.append("    return o\n")
    return _compiled("".join(lines), env, "build")


def _repr(self: Any) -> str:
    items = ", ".join(f"{f.name}={getattr(self, f.name)!r}" for f in fields(self) if f.repr)
    return f"{type(self).__qualname__}({items})"


def _eq(self: Any, other: object) -> bool:
    if other.__class__ is not self.__class__:
        return NotImplemented
    return _values(self) == _values(other)


def _hash(self: Any) -> int:
    return hash(_values(self))


def _setstate(self: Any, state: tuple[Any, ...]) -> None:
    for name, value in zip(_names(type(self)), state, strict=True):
        object.__setattr__(self, name, value)


def _parameters(cls: type, slow: Callable[..., None], env: dict[str, Any]
                ) -> tuple[list[str], dict[str, str]] | None:
    """What generated code needs of dataclass's `__init__` (`slow`) of `cls`: its parameters
    as source, their defaults bound in `env` (as `_d_NAME`), and for each field the expression
    of its value (a default_factory, as `_f_NAME`, called for dataclass's sentinel); None when
    the fields are not the parameters (InitVar or init=False fields)."""
    code, own = slow.__code__, fields(cls)  # type: ignore[arg-type]
    params = code.co_varnames[1:code.co_argcount + code.co_kwonlyargcount]
    if sorted(params) != sorted(f.name for f in own) or not all(f.init for f in own):
        return None
    positional, keyword = params[:code.co_argcount - 1], params[code.co_argcount - 1:]
    defaults = dict(zip(positional[len(positional) - len(slow.__defaults__ or ()):],
                        slow.__defaults__ or (), strict=True))
    defaults.update(slow.__kwdefaults__ or {})

    def param(name: str) -> str:
        if name not in defaults:
            return name
        env[f"_d_{name}"] = defaults[name]
        return f"{name}=_d_{name}"

    values = {}
    for f in own:
        values[f.name] = f.name
        if f.default_factory is not MISSING:  # its parameter's default is dataclass's sentinel
            env[f"_f_{f.name}"] = f.default_factory
            values[f.name] = f"_f_{f.name}() if {f.name} is _d_{f.name} else {f.name}"
    return [*map(param, positional), *(["*", *map(param, keyword)] if keyword else [])], values


def _compiled(source: str, env: dict[str, Any], name: str) -> Callable[..., Any]:
    namespace: dict[str, Any] = {}
    exec(compile(source, "<record>", "exec"), env, namespace)
    return namespace[name]  # type: ignore[no-any-return]


def _fast_init(cls: type, slow: Callable[..., None]) -> Callable[..., None]:
    """dataclass's `__init__` of the slots record `cls` (`slow`), written with the slots'
    setters: the same parameters and defaults (taken from `slow`), each default_factory
    called for its sentinel, the fields set in order, then `__post_init__`. `slow` itself
    for what it does not cover (InitVar or init=False fields, fields kept in a __dict__)."""
    own = fields(cls)  # type: ignore[arg-type]
    setters = [getattr(cls, f.name, None) for f in own]
    env: dict[str, Any] = {}
    found = _parameters(cls, slow, env)
    if found is None or not all(isinstance(s, types.MemberDescriptorType) for s in setters):
        return slow
    params, values = found
    body = []
    for f, setter in zip(own, setters, strict=True):
        env[f"_s_{f.name}"] = setter.__set__  # type: ignore[union-attr]
        body.append(f"    _s_{f.name}(self, {values[f.name]})\n")
    if hasattr(cls, "__post_init__"):
        body.append("    self.__post_init__()\n")
    fast = _compiled(f"def __init__({', '.join(['self', *params])}):\n{''.join(body) or '    pass'}",
                     env, "__init__")
    # inspect.signature shows slow's
    fast.__qualname__, fast.__wrapped__ = slow.__qualname__, slow  # type: ignore[attr-defined]
    return fast


def _first_init(cls: type, slow: Callable[..., None]) -> Callable[..., None]:
    """An `__init__` that puts `_fast_init` in its place when the first record is made: most
    records of mpc are never made in a process, and each exec costs 0.1 ms."""

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        fast = _fast_init(cls, slow)
        cls.__init__ = fast  # type: ignore[misc]
        fast(self, *args, **kwargs)

    __init__.__qualname__, __init__.__wrapped__ = slow.__qualname__, slow  # type: ignore[attr-defined]
    return __init__


_MAKERS: dict[type, Callable[..., Any]] = {}


def maker(cls: type[R]) -> Callable[..., R]:
    """A function that makes a `cls` as `cls(...)` would (the same parameters, defaults,
    default_factory and __post_init__), in a quarter of the time, for code that makes many
    (the readers): it fills an unfrozen twin of `cls` (the same slots, so each assignment is
    the interpreter's direct slot store) and then makes it a `cls`; no class call, whose
    keyword arguments go through a dict. Only for a record made in bulk (`bulk=True`; a
    TypeError for any other); `cls` itself for one it does not cover (a base class, InitVar
    or init=False fields, an __init__ of its own)."""
    make = _MAKERS.get(cls)
    if make is None:
        if cls not in _BULK:
            raise TypeError(f"{cls.__qualname__} is not made in bulk: maker serves only "
                            "@record(slots=True, bulk=True) classes")
        make = _MAKERS[cls] = _maker(cls)
    return make


def _maker(cls: Any) -> Callable[..., Any]:
    init = cls.__init__
    slow = getattr(init, "__wrapped__", None)  # dataclass's, behind _first_init or _fast_init
    own = fields(cls)
    if (slow is None or cls.__bases__ != (object,)
            or getattr(cls, "__slots__", None) != tuple(f.name for f in own)):
        return cls  # type: ignore[no-any-return]
    env: dict[str, Any] = {"_cls": cls, "_twin": type(cls.__name__, (), {"__slots__": cls.__slots__})}
    found = _parameters(cls, slow, env)
    if found is None:
        return cls  # type: ignore[no-any-return]
    params, values = found
    lines = [f"def make({', '.join(params)}):\n", "    self = _twin()\n"]
    lines += [f"    self.{f.name} = {values[f.name]}\n" for f in own]
    lines.append("    self.__class__ = _cls\n")
    if hasattr(cls, "__post_init__"):
        lines.append("    self.__post_init__()\n")
    lines.append("    return self\n")
    make = _compiled("".join(lines), env, "make")
    make.__qualname__ = f"{cls.__qualname__}.make"
    return make


@overload
def record(cls: T, /) -> T: ...
@overload
def record(*, slots: bool = False, kw_only: bool = False, bulk: bool = False) -> Callable[[T], T]: ...


@dataclass_transform(frozen_default=True)
def record(cls: Any = None, /, *, slots: bool = False, kw_only: bool = False, bulk: bool = False) -> Any:
    """`@dataclass(frozen=True, …)` with repr, == and hash from this module. bulk: a class a
    reader makes by the thousand, given the fast `__init__` and a `maker` (needs slots)."""
    if bulk and not slots:
        raise TypeError("@record(bulk=True) needs slots=True")

    def wrap(c: T) -> T:
        written = "__init__" in c.__dict__
        out = dataclass(c, frozen=True, repr=False, eq=False, slots=slots, kw_only=kw_only)
        methods = [("__repr__", _repr), ("__eq__", _eq), ("__hash__", _hash)]
        if slots:  # dataclass's own look each field up anew for every object pickled
            methods += [("__getstate__", _values), ("__setstate__", _setstate)]
        for name, method in methods:
            if name not in c.__dict__:
                setattr(out, name, method)
        if bulk and not written:  # dataclass wrote it
            out.__init__ = _first_init(out, out.__init__)  # type: ignore[misc]
            _BULK.add(out)
        _RECORDS.add(out)
        return out

    return wrap if cls is None else wrap(cls)
