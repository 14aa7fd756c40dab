"""Canonical URDF output: byte-stable, a fixed point of read → emit, exact numbers."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from lxml import etree

from mpc.backends import urdf
from mpc.backends.xml import fmt_float
from mpc.core.diagnostics import Sink
from mpc.ir.geometry import Mesh
from tests.backends.test_urdf_real_models import GOOD
from tests.conftest import ERD, Diags, compile_file, definition, write


def _by_uri(mesh: Mesh) -> str:
    return mesh.source.uri


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_compiling_twice_gives_identical_bytes(tmp_path: Path) -> None:
    spec = write(tmp_path / "talos.yml",
                 definition(ERD / "talos_data/robots/talos_full_v2.urdf", "stl", "talos"))
    first = compile_file(spec, tmp_path / "a", Diags()).out
    second = compile_file(spec, tmp_path / "b", Diags()).out
    assert first and second
    a, b = _files(first), _files(second)
    assert len(a) == 55  # the URDF, its SMURF (.smurf and 5 category files) and 48 distinct STL files
    assert a == b


@pytest.mark.parametrize("model", GOOD)
def test_emit_is_a_fixed_point_of_read_and_emit(model: str, tmp_path: Path) -> None:
    sink = Sink()
    robot = urdf.read(ERD / model, sink)
    assert robot is not None
    once = urdf.to_string(robot, _by_uri)
    (tmp_path / "once.urdf").write_text(once)
    again = urdf.read(tmp_path / "once.urdf", Sink())
    assert again is not None
    assert urdf.to_string(again, _by_uri) == once


@pytest.mark.parametrize("model", GOOD)
def test_nothing_is_lost(model: str, tmp_path: Path) -> None:
    """Same elements, attributes and comments as the source, counted over the whole file."""
    robot = urdf.read(ERD / model, Sink())
    assert robot is not None
    out = etree.fromstring(urdf.to_string(robot, _by_uri).encode())
    src = etree.parse(str(ERD / model)).getroot()

    def census(root: etree._Element) -> Counter[str]:
        c: Counter[str] = Counter()
        for el in root.iter():
            if el.tag is etree.Comment:
                c["<!-- " + " ".join(str(el.text).split()) + " -->"] += 1
            elif isinstance(el.tag, str):
                c[str(el.tag)] += 1
                c.update(f"{el.tag}@{a}" for a in el.attrib)
        return c

    def prolog(root: etree._Element) -> list[str]:
        return [str(c.text) for c in root.itersiblings(preceding=True) if c.tag is etree.Comment]

    assert census(out) == census(src)
    assert prolog(out) == prolog(src)


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_numbers_read_back_exactly(x: float) -> None:
    assert float(fmt_float(x)) == x or (x == 0 and fmt_float(x) == "0")


def test_numbers_are_short() -> None:
    assert [fmt_float(x) for x in (0.0, -0.0, 1.0, -2.0, 0.1, 1e-6, math.pi, 1e16)] == [
        "0", "0", "1", "-2", "0.1", "1e-06", "3.141592653589793", "1e+16"]
    # the largest integers written whole, the smallest with an exponent; not finite as Python
    # writes it; numpy's floats as Python's (a computed inertia may be one)
    assert [fmt_float(x) for x in (1e15, -9007199254740992.0, 1.5e16, float("inf"), -float("inf"))] == [
        "1000000000000000", "-9007199254740992", "1.5e+16", "inf", "-inf"]
    assert [fmt_float(x) for x in (np.float64(3.0), np.float64(-1e15), np.float64(0.0))] == [
        "3", "-1000000000000000", "0"]
