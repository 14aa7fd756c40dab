"""`@record` behaves as `@dataclass(frozen=True)` would: repr, ==, hash, immutability."""

from __future__ import annotations

import dataclasses

import pytest

from mpc.core.record import record
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
