"""The textual IR: dump → parse gives the same Program back, and bad IR text gets located diagnostics.

The property test draws programs from the type hints of the registry, so every op in
OPS (including ops added later) is covered without changes here. Two test-only ops
exercise what real ops may not have yet: nested dataclasses, unions of dataclasses,
tuples, Optional, Mapping, frozenset, Literal, Path, Span and untyped values.
"""

from __future__ import annotations

import functools
import math
import types
from collections import abc
from collections.abc import Iterator, Mapping
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any, Literal, Union, get_args, get_origin

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mpc.compiler.driver import Options
from mpc.compiler.front_end import front_end
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.ops import OPS, Op
from mpc.ir.program import Program
from mpc.ir.robot import Pose
from mpc.ir.text import dump, parse
from mpc.ir.text_types import field_hints, registry, unwrap
from tests.conftest import Diags

TALOS = Path(__file__).resolve().parents[2] / "examples" / "talos.yml"


# Test-only ops. They register in OPS when defined; they are taken out again at once and
# put back only while this module's tests run, so other tests never see them.

@dataclass(frozen=True, slots=True, kw_only=True)
class _TestLimits:
    """A nested dataclass with an optional field."""

    lower: float
    upper: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class _TestSpec:
    """A nested dataclass holding other dataclasses, a mapping and a span."""

    pose: Pose = field(default_factory=Pose)
    limits: tuple[_TestLimits, ...] = ()
    gains: Mapping[str, float] = field(default_factory=dict)
    where: Span | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class _TestBox:
    size: tuple[float, float, float]


@dataclass(frozen=True, slots=True, kw_only=True)
class _TestSphere:
    radius: float


@dataclass(frozen=True, kw_only=True)
class _TestNestedOp(Op):
    """Every kind of field the textual IR supports."""

    spec: _TestSpec
    xyz: tuple[float, float, float]
    at: Span
    values: tuple[float, ...] = ()
    count: int | None = None
    mode: Literal["a", "b", 3] = "a"
    file: Path | None = None
    table: Mapping[str, float] = field(default_factory=dict)
    flags: frozenset[str] = frozenset()
    anything: tuple[object, ...] = ()


@dataclass(frozen=True, kw_only=True)
class _TestUnionOp(Op):
    """Unions: of dataclasses, of a tuple and None, of scalars."""

    shape: _TestBox | _TestSphere
    vec: tuple[float, float, float] | None = None
    pairs: tuple[tuple[str, str], ...] = ()
    number: int | float | str = 0


@dataclass(frozen=True, kw_only=True)
class _TestCheckedOp(Op):
    """An op whose class refuses some values (used by one test only)."""

    radius: float

    def __post_init__(self) -> None:
        if self.radius < 0:
            raise ValueError(f"radius must not be negative, got {self.radius}")


TEST_OPS: tuple[type[Op], ...] = (_TestNestedOp, _TestUnionOp)
for _cls in (*TEST_OPS, _TestCheckedOp):
    del OPS[_cls.kind]


@pytest.fixture(autouse=True, scope="module")
def _test_ops() -> Iterator[None]:
    OPS.update({cls.kind: cls for cls in TEST_OPS})
    yield
    for cls in TEST_OPS:
        OPS.pop(cls.kind, None)


# Strategies, derived from type hints.

TRICKY = ['"', "\\", 'a"b\\c\n', "é", "\u2028", "\x00", "\x7f", "😀", "\ud800", "\t",
          'path("x")', "@ f:1:1-1:1", "# not a comment", "", " ", "none", "true", "-inf"]
TEXT = st.text(max_size=12) | st.sampled_from(TRICKY)
FLOATS = st.floats(allow_nan=False) | st.sampled_from(
    [-0.0, 0.0, 1e-300, 5e-324, math.inf, -math.inf, 1e16, 0.1, 1.7976931348623157e308])
SPANS = st.builds(Span, TEXT | st.sampled_from(["examples/talos.yml", "a b.yml", "C:\\x.yml"]),
                  *(st.integers(0, 10**6) for _ in range(4)))
SCALARS = st.none() | st.booleans() | st.integers() | FLOATS | TEXT


def strategy(hint: Any) -> st.SearchStrategy[Any]:
    """Values of the type `hint`, for any hint the IR supports."""
    hint = unwrap(hint)
    origin, args = get_origin(hint), get_args(hint)
    if hint is Any or hint is object:
        return SCALARS
    if origin in (Union, types.UnionType):
        return st.one_of(*(strategy(a) for a in args))
    if origin is Literal:
        return st.sampled_from(args)
    if origin is tuple:
        if args and args[-1] is Ellipsis:
            return st.lists(strategy(args[0]), max_size=3).map(tuple)
        return st.tuples(*(strategy(a) for a in args))
    if origin in (frozenset, abc.Set):
        return st.frozensets(strategy(args[0]), max_size=3)
    if origin in (dict, abc.Mapping):
        return st.dictionaries(strategy(args[0]), strategy(args[1]), max_size=3)
    simple = {type(None): st.none(), bool: st.booleans(), int: st.integers(), float: FLOATS,
              str: TEXT, Path: st.builds(Path, TEXT), Span: SPANS}
    if hint in simple:
        return simple[hint]
    return st.builds(hint, **{name: _field(hint, name, h) for name, h in field_hints(hint).items()})


def _field(cls: type, name: str, hint: Any) -> st.SearchStrategy[Any]:
    """A field's values; its default now and then, so that omitting defaults is exercised."""
    f = next(f for f in fields(cls) if f.name == name)
    default = f.default if f.default is not MISSING else \
        f.default_factory() if f.default_factory is not MISSING else MISSING
    values = st.deferred(lambda: strategy(hint))
    return values if default is MISSING else st.just(default) | values


@functools.cache
def programs() -> st.SearchStrategy[Program]:
    """Programs with random inputs, ops drawn from OPS and exports (one strategy: hypothesis
    validates a strategy when it is first drawn from, which costs more than drawing)."""
    reg = registry()
    rest = {name: _field(Program, name, h) for name, h in field_hints(Program).items()
            if name not in ("inputs", "ops", "exports")}
    return st.builds(
        Program,
        inputs=st.dictionaries(TEXT, strategy(reg.input), max_size=3),
        ops=st.lists(st.one_of(*(strategy(cls) for cls in OPS.values())), max_size=6).map(tuple),
        exports=st.lists(st.one_of(*(strategy(c) for c in reg.exports.values())), max_size=2).map(tuple),
        **rest,
    )


def round_trip(program: Program) -> Program:
    text = dump(program)
    sink = Sink()
    back = parse(text, "test.ir", sink)
    assert not sink.diagnostics, [f"{d.span}: {d.code}: {d.message}" for d in sink] + text.splitlines()
    assert back is not None
    assert dump(back) == text  # also catches what == cannot see: -0.0 against 0.0
    return back


# Round trips.

@pytest.fixture(scope="module")
def talos() -> Program:
    sink = Sink()
    program = front_end(TALOS, sink, Options())
    assert program is not None, sink.diagnostics
    return program


def test_round_trip_of_a_real_program(talos: Program) -> None:
    assert round_trip(talos) == talos


def test_the_text_has_one_record_a_line_in_order(talos: Program) -> None:
    lines = dump(talos).splitlines()
    assert lines[0] == "# mpc ir 1"
    words = [line.split()[0] for line in lines[1:]]
    assert words == ["program"] + ["input"] * len(talos.inputs) + ["op"] * len(talos.ops) \
        + ["export"] * len(talos.exports)
    assert lines[1].endswith(f"@ {TALOS}:{talos.span.line}:{talos.span.col}-"
                             f"{talos.span.end_line}:{talos.span.end_col}")
    assert f'op set_robot_name name="talos" @ {TALOS}:' in dump(talos)


@settings(suppress_health_check=[HealthCheck.too_slow])  # each program is large
@given(st.data())
def test_round_trip_of_generated_programs(data: st.DataObject) -> None:
    program = data.draw(programs())
    assert round_trip(program) == program


@pytest.mark.parametrize("value", [-0.0, 1e-300, 5e-324, math.inf, -math.inf, 1e16, 2.0**70])
def test_floats_read_back_exactly(value: float, talos: Program) -> None:
    op = _TestUnionOp(span=Span("f"), shape=_TestSphere(radius=value), number=value)
    back = round_trip(Program(**{**_kwargs(talos), "ops": (op,)}))
    assert math.copysign(1, back.ops[0].shape.radius) == math.copysign(1, value)
    assert back.ops[0].number == value and type(back.ops[0].number) is float


def test_nan_reads_back_as_nan(talos: Program) -> None:
    op = _TestUnionOp(span=Span("f"), shape=_TestSphere(radius=math.nan))
    back = round_trip(Program(**{**_kwargs(talos), "ops": (op,)}))
    assert math.isnan(back.ops[0].shape.radius)


def test_nested_values_print_readably(talos: Program) -> None:
    spec = _TestSpec(pose=Pose(xyz=(1.0, 0.0, -0.5)), gains={"kp": 2.0}, where=Span("a b.yml", 3, 4))
    op = _TestNestedOp(span=Span("my file:1.yml", 1, 2, 1, 9), spec=spec, xyz=(0.0, 1.0, 2.0),
                       at=Span("f.yml", 5, 6, 5, 8), file=Path("/m/x.stl"), flags=frozenset({"b", "a"}))
    line = dump(Program(**{**_kwargs(talos), "ops": (op,)})).splitlines()[-len(talos.exports) - 1]
    assert line == (
        'op __test_nested_op spec=_TestSpec(pose=Pose(xyz=[1.0, 0.0, -0.5]), gains={"kp": 2.0}, '
        'where=span("a b.yml", 3, 4, 3, 4)) xyz=[0.0, 1.0, 2.0] at=span("f.yml", 5, 6, 5, 8) '
        'file=path("/m/x.stl") flags=["a", "b"] @ "my file:1.yml":1:2-1:9')


def _kwargs(program: Program) -> dict[str, Any]:
    return {f.name: getattr(program, f.name) for f in fields(program)}


# Diagnostics. Each test appends lines to the real program's text; `line` is the first of them.

def parse_with(talos: Program, extra: str, diags: Diags) -> tuple[Program | None, int]:
    text = dump(talos)
    result = parse(text + extra, "bad.ir", diags)
    return result, text.count("\n") + 1


def located(diags: Diags, code: str) -> tuple[int, int, str]:
    d = diags.take_error(code)
    assert d.span.file == "bad.ir"
    return d.span.line, d.span.col, d.message


def test_syntax_error(talos: Program, diags: Diags) -> None:
    result, line = parse_with(talos, 'op set_robot_name name=="x" @ f:1:1-1:1\n', diags)
    assert result is None
    assert located(diags, "E0230") == (line, 24, "invalid IR: unexpected '='")


def test_unexpected_end_of_line(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op set_robot_name name=[1,\n', diags)
    assert located(diags, "E0230") == (line, 27, "invalid IR: unexpected end of line")


def test_unknown_op_kind_suggests_the_nearest(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op set_robotname name="x" @ f:1:1-1:1\n', diags)
    assert located(diags, "E0231") == (
        line, 4, "unknown op kind 'set_robotname'; did you mean 'set_robot_name'?")


def test_unknown_record_type(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'opp set_robot_name name="x"\n', diags)
    assert located(diags, "E0231") == (line, 1, "unknown record type 'opp'; did you mean 'op'?")


def test_unknown_field(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op set_robot_name name="x" nmae="y" @ f:1:1-1:1\n', diags)
    assert located(diags, "E0231") == (
        line, 28, "op 'set_robot_name' has no field 'nmae'; did you mean 'name'?")


def test_unknown_nested_type(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op __test_union_op shape=_TestBux(size=[1.0, 2.0, 3.0]) @ f:1:1-1:1\n',
                         diags)
    assert located(diags, "E0231") == (line, 26, "unknown type '_TestBux'; did you mean '_TestBox'?")


def test_wrong_type(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op set_robot_name name=3 @ f:1:1-1:1\n', diags)
    assert located(diags, "E0232") == (
        line, 24, "field 'name' of op 'set_robot_name' must be a string, got 3")


def test_wrong_type_deep_inside_a_value(talos: Program, diags: Diags) -> None:
    extra = ('op __test_nested_op spec=_TestSpec(limits=[_TestLimits(lower="low")]) xyz=[1, 2, 3] '
             'at=span("f", 1, 1, 1, 1) mode="c" @ f:1:1-1:1\n')
    _, line = parse_with(talos, extra, diags)
    assert extra.index('"low"') + 1 == 62
    assert located(diags, "E0232") == (
        line, 62, "field 'lower' of _TestLimits(…) in field 'limits[0]' of _TestSpec(…) in field 'spec' "
                  "of op '__test_nested_op' must be a number, got \"low\"")
    assert located(diags, "E0232") == (
        line, 115, "field 'mode' of op '__test_nested_op' must be one of \"a\", \"b\", 3, got \"c\"")


def test_wrong_length_and_wrong_union_member(talos: Program, diags: Diags) -> None:
    extra = 'op __test_union_op shape=_TestSphere(radius=1) vec=[1.0, 2.0] number=[] @ f:1:1-1:1\n'
    _, line = parse_with(talos, extra, diags)
    assert (extra.index("[1.0") + 1, extra.index("[]") + 1) == (52, 70)
    assert located(diags, "E0232") == (
        line, 52, "field 'vec' of op '__test_union_op' must be a list of 3 items, got a list of 2 items")
    assert located(diags, "E0232") == (
        line, 70, "field 'number' of op '__test_union_op' must be an integer or a number or a string, "
                  "got a list of 0 items")


def test_missing_required_field(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, "op set_robot_name @ f:1:1-1:1\n", diags)
    assert located(diags, "E0233") == (line, 1, "op 'set_robot_name' is missing required field 'name'")


def test_duplicate_input(talos: Program, diags: Diags) -> None:
    name = next(iter(talos.inputs))
    _, line = parse_with(talos, f'input {name} kind="basefile" path=none @ f:1:1-1:1\n', diags)
    assert located(diags, "E0234")[:2] == (line, 7)


def test_a_value_the_class_refuses(talos: Program, diags: Diags, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(OPS, _TestCheckedOp.kind, _TestCheckedOp)
    _, line = parse_with(talos, "op __test_checked_op radius=-1.5 @ f:1:1-1:1\n", diags)
    assert located(diags, "E0234") == (
        line, 1, "op '__test_checked_op' cannot be built: radius must not be negative, got -1.5")


def test_a_field_given_twice(talos: Program, diags: Diags) -> None:
    _, line = parse_with(talos, 'op set_robot_name name="x" name="y" @ f:1:1-1:1\n', diags)
    assert located(diags, "E0234") == (line, 28, "op 'set_robot_name' has field 'name' twice")


def test_every_error_in_a_file_is_reported(talos: Program, diags: Diags) -> None:
    result, line = parse_with(talos, 'op set_robot_name name=="x"\n'
                                     '\n'
                                     'op set_robot_name name="x" nmae="y" @ f:1:1-1:1\n'
                                     'op set_robot_name name=3 @ f:1:1-1:1\n', diags)
    assert result is None
    assert located(diags, "E0230")[:2] == (line, 24)
    assert located(diags, "E0231")[:2] == (line + 2, 28)
    assert located(diags, "E0232")[:2] == (line + 3, 24)


def test_a_later_version_is_refused(talos: Program, diags: Diags) -> None:
    text = dump(talos).replace("# mpc ir 1", "# mpc ir 2")
    assert parse(text, "bad.ir", diags) is None
    assert located(diags, "E0230") == (1, 1, "invalid IR: version 2 is not supported "
                                             "(this mpc reads version 1)")


def test_a_file_without_a_program_line(diags: Diags) -> None:
    assert parse("# mpc ir 1\n", "bad.ir", diags) is None
    assert located(diags, "E0233") == (1, 1, "the IR has no 'program' line")
