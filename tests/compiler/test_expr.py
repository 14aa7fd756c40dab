"""mpc.compiler.expr: numbers written in definitions → floats, or E0210–E0214 at the right column."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

import mpc.compiler.expr
from mpc.compiler.expr import Binary, Call, Name, Num, Unary, evaluate, parse
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.core.yaml_source import load
from tests.conftest import Diags, write

WHAT = "joint 'j1' max"
NOWHERE = Span("<test>", 1, 1)
_files = itertools.count()


def ev_yaml(tmp_path: Path, diags: Diags, yaml_text: str, path: tuple[str, ...] = ("max",)) -> float | None:
    """Evaluate the value at `path` in a YAML file of `yaml_text`, with its real span."""
    doc = load(write(tmp_path / f"def{next(_files)}.yml", yaml_text), diags)
    assert doc is not None
    value = doc.data
    for key in path:
        value = value[key]
    return evaluate(value, doc.values[path], diags, what=WHAT)


def where(diags: Diags, code: str) -> tuple[str, str]:
    """Take the error `code`: ('line:col', message)."""
    d = diags.take_error(code)
    return f"{d.span.line}:{d.span.col}", d.message


def ev(value: object) -> float | None:
    sink = Sink()
    result = evaluate(value, NOWHERE, sink)
    assert not sink.diagnostics, [d.message for d in sink]
    return result


# Values


@pytest.mark.parametrize(("value", "expected"), [
    (3, 3.0), (-1.5, -1.5), (0, 0.0),
    ("2*pi", 2 * math.pi), ("-pi/2", -math.pi / 2), ("pi/4 + 0.1", math.pi / 4 + 0.1),
    ("(1+2)*3", 9.0), ("2+3*4", 14.0), ("2*3+4", 10.0), ("10-4-3", 3.0), ("8/4/2", 1.0),
    ("-2**2", -4.0), ("(-2)**2", 4.0), ("2**3**2", 512.0), ("2**-1", 0.5), ("+3", 3.0), ("--3", 3.0),
    ("((1+2)*(3-(4/2)))", 3.0), ("1e-3", 0.001), (".5", 0.5), ("3.", 3.0), ("2.5E2", 250.0),
    ("deg(180)", math.pi), ("rad(-1)", -1.0), ("sqrt(16)", 4.0), ("abs(-2)", 2.0),
    ("sin(0)", 0.0), ("cos(0)", 1.0), ("tan(0)", 0.0), ("asin(1)", math.pi / 2), ("acos(1)", 0.0),
    ("atan(1)", math.pi / 4), ("atan2(1, 1)", math.pi / 4), ("min(3, 1, 2)", 1.0), ("max(3, 1)", 3.0),
    (" 2 * pi ", 2 * math.pi), ("pi/4 +\n0.1\n", math.pi / 4 + 0.1),
    (["deg", 90], math.pi / 2), (["deg", 180], math.pi), (["rad", -1], -1.0), (["rad", "pi/2"], math.pi / 2),
    (["deg", "90*2"], math.pi),
])
def test_value(value: object, expected: float) -> None:
    result = ev(value)
    assert type(result) is float
    assert result == expected


def test_values_from_yaml(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: deg(180)\n") == math.pi
    assert ev_yaml(tmp_path, diags, 'max: "-pi/2"\n') == -math.pi / 2
    assert ev_yaml(tmp_path, diags, "max: [deg, 90]\n") == math.pi / 2
    assert ev_yaml(tmp_path, diags, "max: 1e-3\n") == 0.001
    assert ev_yaml(tmp_path, diags, "max: |\n  pi/4 +\n  0.1\n") == math.pi / 4 + 0.1


def test_tree() -> None:
    assert parse("-2**x") == Unary("-", Binary("**", Num(2.0, 1, 2), Name("x", 4, 5), 1, 5), 0, 5)
    assert parse("f(1, (2))") == Call("f", (Num(1.0, 2, 3), Num(2.0, 6, 7)), 0, 9)
    assert parse("g()") == Call("g", (), 0, 3)
    one_two = Binary("+", Num(1.0, 1, 2), Num(2.0, 3, 4), 1, 4)  # its parentheses are the product's
    assert parse("(1+2)*3") == Binary("*", one_two, Num(3.0, 6, 7), 0, 7)


# E0210 syntax errors: the column of the offending character inside the string


def test_syntax_error_quoted(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, 'max: "2*/pi"\n') is None
    assert where(diags, "E0210") == ("1:9", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


def test_syntax_error_single_quoted(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: '2 */pi'\n") is None
    assert where(diags, "E0210") == ("1:10", "invalid expression '2 */pi' for joint 'j1' max: unexpected '/'")


def test_syntax_error_plain(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: 2*/pi  # a comment\n") is None
    assert where(diags, "E0210") == ("1:8", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


def test_syntax_error_nested(tmp_path: Path, diags: Diags) -> None:
    text = 'joints:\n  j1:\n    max: "(1+2))"\n'
    assert ev_yaml(tmp_path, diags, text, ("joints", "j1", "max")) is None
    assert where(diags, "E0210") == ("3:16", "invalid expression '(1+2))' for joint 'j1' max: unexpected ')'")


def test_power_caret(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: 2^3\n") is None
    d = diags.take_error("E0210")
    assert (d.span.line, d.span.col, d.span.end_col) == (1, 7, 8)
    assert d.message == "invalid expression '2^3' for joint 'j1' max: unexpected '^'"
    assert d.hint == "use ** for powers"


def test_unexpected_end(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, 'max: "1 +"\n') is None
    assert where(diags, "E0210") == ("1:10", "invalid expression '1 +' for joint 'j1' max: "
                                             "unexpected end of expression")
    assert ev_yaml(tmp_path, diags, "max: sqrt(2\n") is None
    assert where(diags, "E0210") == ("1:12", "invalid expression 'sqrt(2' for joint 'j1' max: "
                                             "unexpected end of expression")


def test_unexpected_number(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: 2 3\n") is None
    assert where(diags, "E0210") == ("1:8", "invalid expression '2 3' for joint 'j1' max: unexpected '3'")


def test_empty(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, 'max: ""\n') is None
    assert where(diags, "E0210") == ("1:6", "empty expression for joint 'j1' max")


def test_syntax_error_in_flow_pair(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, 'max: [deg, "2*/pi"]\n') is None
    assert where(diags, "E0210") == ("1:15", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


def test_syntax_error_block_scalar_points_at_value(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: |\n  2*/pi\n") is None
    assert where(diags, "E0210") == ("1:6", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


def test_escaped_scalar_points_at_value(tmp_path: Path, diags: Diags) -> None:
    # The text "2*/pi" is not written as such on the line, so no column inside it is trusted.
    assert ev_yaml(tmp_path, diags, 'max: "2*\\x2Fpi"\n') is None
    assert where(diags, "E0210") == ("1:6", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


def test_unreadable_file_assumes_unquoted(diags: Diags) -> None:
    assert evaluate("2*/pi", Span("missing.yml", 4, 10, 4, 15), diags, what=WHAT) is None
    assert where(diags, "E0210") == ("4:12", "invalid expression '2*/pi' for joint 'j1' max: unexpected '/'")


# E0211 unknown names, E0212 unknown functions and arity


def test_unknown_name(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, 'max: "2*pie"\n') is None
    d = diags.take_error("E0211")
    assert (d.span.line, d.span.col, d.span.end_col) == (1, 9, 12)
    assert d.message == "unknown name 'pie' in expression for joint 'j1' max; did you mean 'pi'?"


def test_every_unknown_name_is_reported(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: e + sqrt\n") is None
    assert where(diags, "E0211") == ("1:6", "unknown name 'e' in expression for joint 'j1' max")
    d = diags.take_error("E0211")
    assert (d.span.col, d.message) == (10, "unknown name 'sqrt' in expression for joint 'j1' max")
    assert d.hint == "'sqrt' is a function: write sqrt(…)"


def test_unknown_function(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: 1 + sqr(2)\n") is None
    assert where(diags, "E0212") == ("1:10", "unknown function 'sqr' in expression for joint 'j1' max; "
                                             "did you mean 'sqrt'?")


@pytest.mark.parametrize(("text", "message"), [
    ("atan2(1)", "function 'atan2' takes 2 arguments but got 1 in expression for joint 'j1' max"),
    ("sin(1, 2)", "function 'sin' takes 1 argument but got 2 in expression for joint 'j1' max"),
    ("deg()", "function 'deg' takes 1 argument but got 0 in expression for joint 'j1' max"),
    ("min(1)", "function 'min' takes at least 2 arguments but got 1 in expression for joint 'j1' max"),
])
def test_arity(tmp_path: Path, diags: Diags, text: str, message: str) -> None:
    assert ev_yaml(tmp_path, diags, f'max: "{text}"\n') is None
    assert where(diags, "E0212") == ("1:7", message)


# E0213 math errors


@pytest.mark.parametrize(("text", "col", "reason"), [
    ("1 + 1/0", 10, "division by zero"),
    ("sqrt(-1)", 6, "sqrt(-1) is undefined"),
    ("2*acos(2)", 8, "acos(2) is undefined"),
    ("(-8)**(1/3)", 6, "(-8) ** 0.333333 is undefined"),
    ("0**-1", 6, "0 ** (-1) is undefined"),
    ("10**400", 6, "the result is too large"),
    ("1e308*10", 6, "the result is not finite"),
])
def test_math_error(tmp_path: Path, diags: Diags, text: str, col: int, reason: str) -> None:
    assert ev_yaml(tmp_path, diags, f"max: {text}\n") is None
    assert where(diags, "E0213") == (f"1:{col}", f"cannot evaluate '{text}' for joint 'j1' max: {reason}")


def test_infinite_number(tmp_path: Path, diags: Diags) -> None:
    assert ev_yaml(tmp_path, diags, "max: .inf\n") is None
    assert where(diags, "E0213") == ("1:6", "joint 'j1' max must be a finite number, got inf")


# E0214 wrong types


@pytest.mark.parametrize(("yaml_value", "message"), [
    ("true", "joint 'j1' max must be a number, got true"),
    ("null", "joint 'j1' max must be a number, got null"),
    ("{a: 1}", "joint 'j1' max must be a number, got a mapping"),
    ("[1, 2, 3]", "joint 'j1' max must be a number or a [unit, value] pair like [deg, 90], "
                  "got a list of 3 items"),
    ("[degs, 90]", "unknown unit 'degs' for joint 'j1' max; did you mean 'deg'?"),
    ("[1, 90]", "unknown unit '1' for joint 'j1' max"),
    ("[deg, [rad, 1]]", "the value in [deg, …] for joint 'j1' max must be a number, got a list"),
    ("[deg, false]", "joint 'j1' max must be a number, got false"),
])
def test_wrong_type(tmp_path: Path, diags: Diags, yaml_value: str, message: str) -> None:
    assert ev_yaml(tmp_path, diags, f"max: {yaml_value}\n") is None
    assert where(diags, "E0214") == ("1:6", message)


def test_default_what(diags: Diags) -> None:
    assert evaluate(None, NOWHERE, diags) is None
    assert diags.take_error("E0214").message == "value must be a number, got null"


# Properties


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_repr_round_trip(x: float) -> None:
    assert ev(repr(x)) == x


@dataclass(frozen=True)
class Op:
    """A test-side expression tree: op applied to args (a leaf when op is '')."""

    op: str
    args: tuple[Op | int, ...]


PREC = {"+": 1, "-": 1, "*": 2, "/": 2, "neg": 3, "**": 4}


def leaf() -> st.SearchStrategy[int]:
    return st.integers(0, 9)


def trees(children: st.SearchStrategy[Op | int]) -> st.SearchStrategy[Op | int]:
    return st.one_of(
        st.builds(lambda o, a, b: Op(o, (a, b)), st.sampled_from("+-*"), children, children),
        st.builds(lambda a, b: Op("/", (a, b)), children, st.integers(1, 9)),
        st.builds(lambda a, b: Op("**", (a, b)), children, st.integers(0, 3)),
        st.builds(lambda a: Op("neg", (a,)), children),
    )


def render(t: Op | int) -> tuple[str, int]:
    """Source text with only the parentheses Python's precedence needs, and its precedence."""
    if isinstance(t, int):
        return str(t), 5
    p = PREC[t.op]

    def wrap(child: Op | int, least: int) -> str:
        text, q = render(child)
        return text if q >= least else f"({text})"

    if t.op == "neg":
        return "-" + wrap(t.args[0], 3), 3
    if t.op == "**":  # right-associative; the base binds tighter than a sign
        return f"{wrap(t.args[0], 5)}**{wrap(t.args[1], 3)}", p
    return f"{wrap(t.args[0], p)} {t.op} {wrap(t.args[1], p + 1)}", p


def compute(t: Op | int) -> float:
    if isinstance(t, int):
        return float(t)
    values = [compute(a) for a in t.args]
    if t.op == "neg":
        return -values[0]
    a, b = values
    return {"+": a + b, "-": a - b, "*": a * b, "/": a / b, "**": a**b}[t.op]  # type: ignore[return-value]


@given(st.recursive(leaf(), trees, max_leaves=12))
def test_arithmetic_trees(tree: Op | int) -> None:
    try:
        expected = compute(tree)
    except (OverflowError, ZeroDivisionError):
        return  # the evaluator's math errors are tested above
    text, _ = render(tree)
    sink = Sink()
    result = evaluate(text, NOWHERE, sink)
    if not math.isfinite(expected):
        assert result is None and [d.code for d in sink] == ["E0213"]
    else:
        assert not sink.diagnostics, [d.message for d in sink]
        assert result == expected, text


def test_no_python_eval() -> None:
    source = Path(mpc.compiler.expr.__file__).read_text(encoding="utf-8")
    assert "eval(" not in source
    assert "exec(" not in source


def test_too_many_operators(diags: Diags) -> None:
    assert evaluate("-" * 5000 + "1", NOWHERE, diags, what=WHAT) is None
    assert diags.take_error("E0210").message == "the expression for joint 'j1' max has too many operators"
