"""`@record`: a frozen dataclass whose methods are written once, here, or when first needed.

`@dataclass` compiles each method it generates with exec() when the class is created:
six for a frozen class, 0.5–0.8 ms a class on our machines. The IR has over a hundred
classes, and every mpc process imports most of them (issue 3: `mpc check` on each editor
save; issue 34: a warm rebuild, 30 ms of its 0.35 s). So dataclass writes no method of a
record: repr, == and hash are the functions below (fields in order, the class's qualified
name, equal only to the same class or its lazy twin (`lazy_twin`), tuple hash), and so are the
frozen `__setattr__` and `__delattr__`; `__init__` is compiled when the first record of the
class is made (most classes are never made in a process), from the class's fields as dataclass
would write it (the same parameters, defaults, default_factory, keyword-only fields,
`__post_init__`), each field set through its slot's own setter where it has one (twice as fast
as object.__setattr__, which dataclass's frozen `__init__` goes through). `dataclasses.fields`,
`replace` and `asdict` and every repr-based digest are unchanged. A record with an InitVar or a
field left out of `__init__` keeps dataclass's own frozen class, and so do its subclasses.

Code that makes records by the thousand (a reader) asks for a `maker`, which skips the class
call too: a quarter of its time. Only classes that opt in with `@record(slots=True,
bulk=True)` have one (`bulk_records()`: the URDF reader's IR values and Span). A record with
slots also pickles its fields as a tuple, in order, as dataclass's own `__getstate__` does,
without looking the fields up for each object. The build cache writes records as their field
values (`record_values`) and reads them back without running their code (`from_values`:
compiler/kept_values.py); only classes made here (`is_record`) are read back.

`@record(frozen=False)` is the same for a mutable class (`@dataclass`'s): repr and == from
here, unhashable, `__init__` compiled for its first object. mpc writes every class of fields
with one or the other, not `@dataclass` (whose methods a process would compile on import).
"""

from __future__ import annotations

import inspect
import types
from collections.abc import Callable
from dataclasses import MISSING, Field, FrozenInstanceError, dataclass, fields
from operator import attrgetter
from typing import Any, TypeVar, dataclass_transform, overload

T = TypeVar("T", bound=type)
R = TypeVar("R")

_NAMES: dict[type, tuple[str, ...]] = {}
_VALUES: dict[type, Callable[[Any], tuple[Any, ...]]] = {}
_RECORDS: set[type] = set()  # every class made by @record
_BULK: set[type] = set()  # those made in bulk: @record(slots=True, bulk=True)
_OWN_INIT: set[type] = set()  # those whose __init__ record writes
_CLASSIC: set[type] = set()  # those that keep dataclass's frozen class (an InitVar, say)
_STANDS_FOR: dict[type, type] = {}  # each lazy twin → the record class it stands for (`lazy_twin`)


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


def lazy_twin(of: type) -> Callable[[T], T]:
    """Class decorator: the decorated subclass of the record class `of` is one of its values
    some of whose fields are found when first asked for (core/span.py: LazySpan; ir/fragments.py:
    LazyFragment). It is no record class of its own (`is_record`): it is equal to, hashes and
    prints as the record of the same fields, and the build cache keeps it, and `settle_spans`
    walks it, as the record it stands for (`record_of`). It pickles and copies as that record
    (every field found first)."""
    def register(cls: T) -> T:
        _STANDS_FOR[cls] = of
        cls.__reduce__ = _reduce_as_record  # type: ignore[method-assign]
        return cls
    return register


def _reduce_as_record(self: Any) -> tuple[Callable[..., Any], tuple[Any, ...]]:
    """A lazy twin's pickle: the record it stands for, made from its fields (`from_values`)."""
    return from_values, (_STANDS_FOR[type(self)], list(_values(self)))


def record_of(cls: type) -> type | None:
    """The record class whose values the objects of `cls` are: `cls` itself, or the record its
    lazy twin stands for (`lazy_twin`); None for any other class."""
    return cls if cls in _RECORDS else _STANDS_FOR.get(cls)


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
    cls = type(self)
    return f"{_STANDS_FOR.get(cls, cls).__qualname__}({items})"  # a lazy twin as its record


def _eq(self: Any, other: object) -> bool:
    mine, theirs = self.__class__, other.__class__
    if theirs is not mine and _STANDS_FOR.get(theirs, theirs) is not _STANDS_FOR.get(mine, mine):
        return NotImplemented  # equal only to the same record (or its lazy twin)
    return _values(self) == _values(other)


def _hash(self: Any) -> int:
    return hash(_values(self))


def _setstate(self: Any, state: tuple[Any, ...]) -> None:
    for name, value in zip(_names(type(self)), state, strict=True):
        object.__setattr__(self, name, value)


class _Factory:
    """The default of a parameter whose field has a default_factory (dataclass's sentinel)."""

    def __repr__(self) -> str:
        return "<factory>"


_FACTORY = _Factory()


def _parameters(cls: type, env: dict[str, Any]) -> tuple[list[str], dict[str, str]]:
    """What an `__init__` of `cls` needs, from its fields as dataclass would make it: its
    parameters as source (positional ones first, then `*` and the keyword-only ones), their
    defaults bound in `env` (as `_d_NAME`), and for each field the expression of its value (a
    default_factory, as `_f_NAME`, called for the sentinel)."""
    own = fields(cls)  # type: ignore[arg-type]
    values = {}

    def param(f: Any) -> str:
        values[f.name] = f.name
        if f.default_factory is not MISSING:
            env[f"_d_{f.name}"], env[f"_f_{f.name}"] = _FACTORY, f.default_factory
            values[f.name] = f"_f_{f.name}() if {f.name} is _d_{f.name} else {f.name}"
        elif f.default is MISSING:
            return f.name
        else:
            env[f"_d_{f.name}"] = f.default
        return f"{f.name}=_d_{f.name}"

    positional = [param(f) for f in own if not f.kw_only]
    keyword = [param(f) for f in own if f.kw_only]
    return [*positional, *(["*", *keyword] if keyword else [])], values


def _compiled(source: str, env: dict[str, Any], name: str) -> Callable[..., Any]:
    namespace: dict[str, Any] = {}
    exec(compile(source, "<record>", "exec"), env, namespace)
    return namespace[name]


def _init(cls: type) -> Callable[..., None]:
    """The `__init__` dataclass would write for the record `cls` (the same parameters, defaults
    and annotations; each default_factory called for its sentinel; the fields set in order, then
    `__post_init__`), each field of a frozen record set through its slot's own setter where it
    has one (twice as fast as object.__setattr__, which the others are set with), each field of
    a mutable one (`_mutable`) assigned."""
    env: dict[str, Any] = {"_set": object.__setattr__}
    params, values = _parameters(cls, env)
    body = []
    mutable = not cls.__dataclass_params__.frozen
    for f in fields(cls):
        setter = getattr(cls, f.name, None)
        if mutable:  # as dataclass's own: a plain assignment
            body.append(f"    self.{f.name} = {values[f.name]}\n")
        elif isinstance(setter, types.MemberDescriptorType):
            env[f"_s_{f.name}"] = setter.__set__
            body.append(f"    _s_{f.name}(self, {values[f.name]})\n")
        else:
            body.append(f"    _set(self, {f.name!r}, {values[f.name]})\n")
    if hasattr(cls, "__post_init__"):
        body.append("    self.__post_init__()\n")
    init = _compiled(f"def __init__({', '.join(['self', *params])}):\n{''.join(body) or '    pass'}",
                     env, "__init__")
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    init.__annotations__ = {**{f.name: f.type for f in fields(cls)}, "return": None}
    return init


def _first_init(cls: type) -> Callable[..., None]:
    """An `__init__` that puts `_init`'s in its place when the first record is made: most
    records of mpc are never made in a process, and each exec costs 0.1 ms."""

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        init = _init(cls)
        cls.__init__ = init  # type: ignore[misc]
        init(self, *args, **kwargs)

    __init__.__qualname__ = f"{cls.__qualname__}.__init__"
    return __init__


def _frozen_setattr(self: Any, name: str, value: Any) -> None:
    """dataclass's frozen `__setattr__`, one for every record."""
    if type(self) in _RECORDS or name in _names(type(self)):
        raise FrozenInstanceError(f"cannot assign to field {name!r}")
    object.__setattr__(self, name, value)


def _frozen_delattr(self: Any, name: str) -> None:
    if type(self) in _RECORDS or name in _names(type(self)):
        raise FrozenInstanceError(f"cannot delete field {name!r}")
    object.__delattr__(self, name)


_MAKERS: dict[type, Callable[..., Any]] = {}


def maker(cls: type[R]) -> Callable[..., R]:
    """A function that makes a `cls` as `cls(...)` would (the same parameters, defaults,
    default_factory and __post_init__), in a quarter of the time, for code that makes many
    (the readers): it fills an unfrozen twin of `cls` (the same slots, so each assignment is
    the interpreter's direct slot store) and then makes it a `cls`; no class call, whose
    keyword arguments go through a dict. Only for a record made in bulk (`bulk=True`; a
    TypeError for any other); `cls` itself for one it does not cover (a base class, one whose
    `__init__` is dataclass's or its own)."""
    make = _MAKERS.get(cls)
    if make is None:
        if cls not in _BULK:
            raise TypeError(f"{cls.__qualname__} is not made in bulk: maker serves only "
                            "@record(slots=True, bulk=True) classes")
        make = _MAKERS[cls] = _maker(cls)
    return make


def _maker(cls: Any) -> Callable[..., Any]:
    own = fields(cls)
    if (cls not in _OWN_INIT or cls.__bases__ != (object,)
            or getattr(cls, "__slots__", None) != tuple(f.name for f in own)):
        return cls  # type: ignore[no-any-return]
    env: dict[str, Any] = {"_cls": cls, "_twin": type(cls.__name__, (), {"__slots__": cls.__slots__})}
    params, values = _parameters(cls, env)
    lines = [f"def make({', '.join(params)}):\n", "    self = _twin()\n"]
    lines += [f"    self.{f.name} = {values[f.name]}\n" for f in own]
    lines.append("    self.__class__ = _cls\n")
    if hasattr(cls, "__post_init__"):
        lines.append("    self.__post_init__()\n")
    lines.append("    return self\n")
    make = _compiled("".join(lines), env, "make")
    make.__qualname__ = f"{cls.__qualname__}.make"
    return make


def _needs_dataclass_init(cls: type) -> bool:
    """Whether the class needs dataclass's own frozen `__init__`: an InitVar or a field left
    out of `__init__` (record's covers neither), or a base that has it."""
    if any(base in _CLASSIC for base in cls.__mro__[1:]):
        return True
    annotations = inspect.get_annotations(cls)  # dataclasses imports inspect
    if any("InitVar" in (a if isinstance(a, str) else repr(a)) for a in annotations.values()):
        return True
    return any(isinstance(v, Field) and not v.init for v in cls.__dict__.values())


def _check_defaults(cls: type) -> None:
    """dataclass's check, which it makes only when it writes `__init__`."""
    default = None
    for f in fields(cls):
        if f.kw_only:
            continue
        if f.default is not MISSING or f.default_factory is not MISSING:
            default = f.name
        elif default is not None:
            raise TypeError(f"non-default argument {f.name!r} follows default argument")


@overload
def record(cls: T, /) -> T: ...
@overload
def record(*, slots: bool = False, kw_only: bool = False, bulk: bool = False,
           frozen: bool = True) -> Callable[[T], T]: ...


@dataclass_transform(frozen_default=True)
def record(cls: Any = None, /, *, slots: bool = False, kw_only: bool = False, bulk: bool = False,
           frozen: bool = True) -> Any:
    """`@dataclass(frozen=True, …)` with its methods from this module. bulk: a class a reader
    makes by the thousand, given a `maker` (needs slots). frozen=False: `@dataclass(…)`, a
    mutable class (`_mutable`)."""
    if bulk and not slots:
        raise TypeError("@record(bulk=True) needs slots=True")
    if not frozen:
        if bulk:
            raise TypeError("@record(bulk=True) is frozen")
        return (lambda c: _mutable(c, slots, kw_only)) if cls is None else _mutable(cls, slots, kw_only)

    def wrap(c: T) -> T:
        classic = _needs_dataclass_init(c)
        # dataclass writes no method, but a classic record's __init__, and the frozen __setattr__
        # and __delattr__ of a record with a dataclass base (which dataclass requires frozen)
        frozen = classic or any(hasattr(base, "__dataclass_fields__") for base in c.__mro__[1:])
        out = dataclass(c, frozen=frozen, init=classic, repr=False, eq=False, slots=slots, kw_only=kw_only)
        methods: list[tuple[str, Any]] = [("__repr__", _repr), ("__eq__", _eq), ("__hash__", _hash)]
        if not frozen:
            methods += [("__setattr__", _frozen_setattr), ("__delattr__", _frozen_delattr)]
            out.__dataclass_params__.frozen = True  # as it is: a frozen dataclass may subclass it
        if slots:  # dataclass's own look each field up anew for every object pickled
            methods += [("__getstate__", _values), ("__setstate__", _setstate)]
        _finish(c, out, methods, classic)
        if bulk:
            _BULK.add(out)
        _RECORDS.add(out)
        return out

    return wrap if cls is None else wrap(cls)


def _mutable(c: T, slots: bool, kw_only: bool) -> T:
    """`@dataclass(slots=…, kw_only=…)` with repr and == from this module and `__init__` compiled
    for the first object made, as a record's: dataclass would compile three methods when the
    class is made (0.2–0.5 ms each class; most of mpc's state classes are imported by every
    process). Unhashable, as dataclass makes a mutable class with ==; no record (`is_record`):
    the build cache reads none back."""
    classic = _needs_dataclass_init(c)
    out = dataclass(c, init=classic, repr=False, eq=False, slots=slots, kw_only=kw_only)
    _finish(c, out, [("__repr__", _repr), ("__eq__", _eq), ("__hash__", None)], classic)
    return out


def _finish(c: type, out: type, methods: list[tuple[str, Any]], classic: bool) -> None:
    """Puts on the class `out` that dataclass made of `c` each of `methods` that `c` does not
    define, and record's `__init__` unless `c` has its own or dataclass wrote it (`classic`)."""
    for name, method in methods:
        if name not in c.__dict__:
            setattr(out, name, method)
    if classic:
        _CLASSIC.add(out)
    elif "__init__" not in c.__dict__:
        _check_defaults(out)
        out.__init__ = _first_init(out)
        _OWN_INIT.add(out)
