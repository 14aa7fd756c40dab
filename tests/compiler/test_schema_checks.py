"""The checks of the schema's types (compiler/schema/checking.py): the conversions of scalars the
language has always made (it was declared in pydantic until issue 34, whose lax mode made them),
the problems they report, and nodes as the walk builds them."""

from __future__ import annotations

import math
import subprocess
import sys
from typing import Any, Literal

import pytest

from mpc.compiler.schema.checking import Invalid, checker
from mpc.core.diagnostics import Sink
from mpc.core.yaml_source import loads


def _check(tp: Any, value: Any) -> Any:
    return checker(tp)(value, None)


def _problem(tp: Any, value: Any) -> str:
    with pytest.raises(Invalid) as e:
        _check(tp, value)
    (error,) = e.value.errors
    assert error["loc"] == () and error["input"] is value
    return error["type"]


@pytest.mark.parametrize(("value", "expected"), [
    (True, True), (False, False), (1, True), (0, False), (1.0, True), (0.0, False),
    ("yes", True), ("Off", False), ("TRUE", True), ("n", False), ("1", True), ("0", False)])
def test_a_bool_takes_what_yaml_users_write_for_one(value: Any, expected: bool) -> None:
    assert _check(bool, value) is expected


@pytest.mark.parametrize(("value", "kind"), [
    (2, "bool_parsing"), (0.5, "bool_parsing"), (math.nan, "bool_parsing"), ("maybe", "bool_parsing"),
    (" yes ", "bool_parsing"),
    ("", "bool_parsing"), (None, "bool_type"), ([], "bool_type"), ({}, "bool_type")])
def test_a_bool_refuses_the_rest(value: Any, kind: str) -> None:
    assert _problem(bool, value) == kind


@pytest.mark.parametrize(("value", "expected"), [
    (3, 3), (-3, -3), (True, 1), (3.0, 3), ("3", 3), (" +3 ", 3), ("-0", 0), ("1_000", 1000),
    ("1.0", 1), ("-0.00", 0), ("00012", 12), (10**30, 10**30)])
def test_an_integer_takes_whole_numbers_however_written(value: Any, expected: int) -> None:
    result = _check(int, value)
    assert result == expected and type(result) is int


@pytest.mark.parametrize(("value", "kind"), [
    (1.5, "int_from_float"), (math.inf, "int_from_float"), (math.nan, "int_from_float"),
    ("1.5", "int_parsing"), ("three", "int_parsing"), ("inf", "int_parsing"), ("1e3", "int_parsing"),
    ("1.", "int_parsing"), ("1__0", "int_parsing"), ("\u0661\u0662", "int_parsing"), ("", "int_parsing"),
    (None, "int_type"),
    ([1], "int_type")])
def test_an_integer_refuses_the_rest_and_says_so(value: Any, kind: str) -> None:
    assert _problem(int, value) == kind


def test_a_string_is_only_a_string() -> None:
    assert _check(str, "1.9") == "1.9"
    assert [_problem(str, v) for v in (1.9, 2, True, None, [])] == ["string_type"] * 5


def test_a_literal_of_numbers_takes_the_number_not_its_text() -> None:
    axis = Literal[0, 1, 2]
    assert [_check(axis, v) for v in (0, 1.0, True)] == [0, 1, 1]
    for value in ("1", 3, 10**23, 1.5):
        with pytest.raises(Invalid) as e:
            _check(axis, value)
        assert e.value.errors[0]["ctx"]["expected"] == "0, 1 or 2"
    with pytest.raises(Invalid) as e:
        _check(Literal["urdf"], "sdf")
    assert e.value.errors[0]["ctx"]["expected"] == "'urdf'"


def test_lists_and_mappings_report_every_bad_item_where_it_is() -> None:
    with pytest.raises(Invalid) as e:
        _check(dict[Literal["a", "b"], list[int]], {"a": [1, "x", 2.5], "c": [1], "b": 4})
    assert [(err["type"], err["loc"]) for err in e.value.errors] == [
        ("int_parsing", ("a", 1)), ("int_from_float", ("a", 2)), ("literal_error", ("c", "[key]")),
        ("list_type", ("b",))]


def _doc(text: str) -> Any:
    doc = loads(text, "m.yml", Sink())
    assert doc is not None
    return doc


def test_nodes_are_frozen_and_their_defaults_their_own() -> None:
    from mpc.compiler.schema.base import validate_as
    from mpc.compiler.schema.editing import Transform

    sink = Sink()
    first = validate_as(Transform, _doc("rpy: [0, 0, 1]\n"), sink, "a transform")
    second = validate_as(Transform, _doc("rpy: [0, 0, 2]\n"), sink, "a transform")
    assert isinstance(first, Transform) and isinstance(second, Transform) and not sink.diagnostics
    assert first.xyz == second.xyz == [0, 0, 0] and first.xyz is not second.xyz
    assert first.given == {"rpy"} and first.rpy == [0, 0, 1]
    with pytest.raises(AttributeError, match="frozen"):
        first.xyz = [1, 2, 3]  # type: ignore[misc]


def test_the_schema_needs_no_pydantic() -> None:
    code = ("import sys\nfrom mpc.compiler.schema import definition\nfrom mpc.compiler import jsonschema\n"
            "jsonschema.definition_schema()\nprint(sorted(m for m in sys.modules if 'pydantic' in m))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout == "[]\n"
