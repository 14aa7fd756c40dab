"""`@record` behaves as `@dataclass(frozen=True)` would: repr, ==, hash, immutability."""

from __future__ import annotations

import dataclasses
import inspect

import pytest

from mpc.core.record import maker, record
from mpc.core.span import Span
from mpc.ir.geometry import Box


@record(slots=True, kw_only=True)
class Pair:
    a: int
    b: tuple[str, ...] = ()


@dataclasses.dataclass(frozen=True, slots=True, kw_only=True)
class DataPair:
    a: int
    b: tuple[str, ...] = ()


@record
class One:
    x: float


def test_repr_eq_and_hash_are_dataclass_ones() -> None:
    mine, theirs = Pair(a=1, b=("x", "y")), DataPair(a=1, b=("x", "y"))
    assert repr(mine) == repr(theirs).replace("DataPair(", "Pair(")
    assert hash(mine) == hash(theirs) == hash((1, ("x", "y")))
    assert mine == Pair(a=1, b=("x", "y")) and mine != Pair(a=2, b=("x", "y"))
    assert mine != theirs  # only the same class is equal
    assert hash(One(2.5)) == hash((2.5,)) and One(2.5) == One(2.5) and repr(One(2.5)) == "One(x=2.5)"


def test_records_are_frozen_dataclasses() -> None:
    pair = Pair(a=1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        pair.a = 2  # type: ignore[misc]
    assert [f.name for f in dataclasses.fields(pair)] == ["a", "b"]
    assert dataclasses.replace(pair, b=("z",)) == Pair(a=1, b=("z",))
    assert not hasattr(pair, "__dict__")  # slots


def test_ir_values_print_as_before() -> None:
    """Mesh digests hash the repr of IR values: it must not change."""
    assert repr(Span("a.yml", 3, 4, 3, 9)) == \
        "Span(file='a.yml', line=3, col=4, end_line=3, end_col=9)"
    box = Box(size=(1.0, 2.0, 3.0))
    assert repr(box) == "Box(size=(1.0, 2.0, 3.0), extra_attrs=())"


@record(slots=True)
class Mixed:
    a: int
    b: str = "b"
    c: list[int] = dataclasses.field(default_factory=list)
    d: tuple[int, ...] = dataclasses.field(default=(), kw_only=True)

    def __post_init__(self) -> None:
        if self.a < 0:
            raise ValueError("a must not be negative")


@record(slots=True)
class Child(Mixed):
    e: float = 0.5


@record(slots=True)
class WithInitVar:
    a: int
    scale: dataclasses.InitVar[int] = 1

    def __post_init__(self, scale: int) -> None:
        object.__setattr__(self, "a", self.a * scale)


def test_slots_records_are_made_as_dataclass_would() -> None:
    """The slots' own setters (record's _fast_init) give what dataclass's __init__ gives:
    defaults, a fresh default_factory value each time, keyword-only fields, __post_init__,
    inherited fields; and the same errors. A record it does not cover keeps dataclass's."""
    for _ in range(2):  # the first record made puts the fast __init__ in place
        assert repr(Mixed(1)) == "Mixed(a=1, b='b', c=[], d=())"
        assert Mixed(1, "x", [2], d=(3,)) == Mixed(a=1, b="x", c=[2], d=(3,))
        assert Mixed(1).c is not Mixed(1).c
        assert Child(1, "y", e=2.0) == Child(a=1, b="y", c=[], d=(), e=2.0)
        assert WithInitVar(2, 3).a == 6
        with pytest.raises(ValueError, match="negative"):
            Mixed(-1)
        with pytest.raises(TypeError, match=r"Mixed.__init__\(\) missing 1 required positional"):
            Mixed()  # type: ignore[call-arg]
        with pytest.raises(TypeError, match="takes from 2 to 4 positional arguments"):
            Mixed(1, "b", [], ())  # type: ignore[misc]
        with pytest.raises(dataclasses.FrozenInstanceError):
            Mixed(1).a = 2  # type: ignore[misc]
    assert Mixed.__init__.__code__.co_filename == Child.__init__.__code__.co_filename == "<record>"
    assert WithInitVar.__init__.__code__.co_filename == "<string>"  # dataclass's
    assert str(inspect.signature(Mixed)) == \
        "(a: 'int', b: 'str' = 'b', c: 'list[int]' = <factory>, *, d: 'tuple[int, ...]' = ()) -> None"


def test_makers_make_what_the_class_makes() -> None:
    """record.maker: the same record as the class call (defaults, a fresh default_factory
    value, keyword-only fields, __post_init__ and its errors), frozen as any; the class itself
    where it does not apply (a base class, InitVar, no slots)."""
    make = maker(Mixed)
    assert make is maker(Mixed) and make is not Mixed
    assert make(1) == Mixed(1) and type(make(1)) is Mixed
    assert make(1, "x", [2], d=(3,)) == Mixed(1, "x", [2], d=(3,))
    assert make(1).c == [] and make(1).c is not make(1).c
    assert maker(Pair)(a=1) == Pair(a=1) and maker(Pair)(a=2, b=("z",)) == Pair(a=2, b=("z",))
    with pytest.raises(ValueError, match="negative"):
        make(-1)
    with pytest.raises(TypeError):
        maker(Pair)(1)  # type: ignore[misc]  (keyword-only, as Pair(1) is)
    with pytest.raises(dataclasses.FrozenInstanceError):
        make(1).a = 2  # type: ignore[misc]
    assert hash(maker(Pair)(a=1)) == hash(Pair(a=1))
    assert maker(Child) is Child and maker(WithInitVar) is WithInitVar
    assert maker(One) is One
    assert maker(Span)("f", 3, 4, 1, 1) == Span("f", 3, 4, 1, 1) == Span("f", 3, 4, 3, 4)  # __post_init__
