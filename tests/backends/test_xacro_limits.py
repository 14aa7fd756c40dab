"""What a xacro expansion may compute is bounded (backends/xacro_limits.py): an operation that
would run or allocate without end in one step is refused before it runs, and an expansion that
runs too long or grows the process too much is stopped; each is E0673, and the process goes on.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from xml.sax.saxutils import escape

import pytest

from mpc.backends import xacro_limits
from mpc.backends.xacro_limits import ExpansionTooLong, bounded_code, watched
from mpc.backends.xacro_reader import expand
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from tests.conftest import write

TAIL = " (a xacro model computes values of the size a robot needs)"


def _expand(tmp_path: Path, body: str) -> tuple[str | None, list[tuple[str, str, int, int]]]:
    xacro = write(tmp_path / "robot.urdf.xacro", '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                  f'  {body}\n  <link name="base"/>\n</robot>\n')
    sink = Sink()
    text = expand(xacro, sink, PackageResolver())
    return text, [(d.code, d.message.split(": ", 1)[1], d.span.line, d.span.col) for d in sink.diagnostics]


@pytest.mark.parametrize(("expression", "why"), [
    ("9**9**9", "its power has more than 1,000,000 bits"),
    ("2**10**7", "its power has more than 1,000,000 bits"),
    ("'a' * 10**12", "it makes a sequence of 1,000,000,000,000 items (more than 10,000,000)"),
    ("[0, 1] * 10**7", "it makes a sequence of 20,000,000 items (more than 10,000,000)"),
    ("10**7 * 'ab'", "it makes a sequence of 20,000,000 items (more than 10,000,000)"),
    ("1 << 10**9", "its shift has more than 1,000,000 bits"),
    ("3**600000 * 3**600000", "its product has more than 1,000,000 bits"),
    ("python.sum(python.range(10**12))", "its range has 1,000,000,000,000 items (more than 10,000,000)"),
    ("python.len(range(1, 10**9, 2))", "its range has 500,000,000 items (more than 10,000,000)"),
    ("math.factorial(10**8)", "factorial(100000000) has more than 1,000,000 bits"),
    ("factorial(10**6)", "factorial(1000000) has more than 1,000,000 bits"),
    ("math.comb(10**9, 10**6)", "comb(1000000000, 1000000) has more than 1,000,000 bits"),
    ("math.prod(python.range(1, 10**6))", "its product has more than 1,000,000 bits"),
    ("'%999999999d' % 1", "its format is wider than 10,000 characters"),
    ("'%.999999999f' % 1.5", "its format is wider than 10,000 characters"),
    ("'%*d' % (10**9, 1)", "its format takes a width from its arguments (`*`)"),
])
def test_an_operation_beyond_its_bound_is_refused_before_it_runs(tmp_path: Path, expression: str,
                                                                 why: str) -> None:
    started = time.monotonic()
    text, said = _expand(tmp_path, f'<link name="${{{escape(expression)}}}"/>')
    assert text is None and said == [("E0673", f"the expression '{expression}' is not evaluated: {why}{TAIL}",
                                      2, 17)]
    assert time.monotonic() - started < 10  # refused, not computed (each would take minutes or more)


def test_values_of_the_size_a_robot_needs_are_computed_as_python_computes_them(tmp_path: Path) -> None:
    expressions = ["2**10", "-2**0.5", "2**-1", "'ab' * 3", "3 * [1]", "1 << 20", "10 % 3",
                   "'%5.2f' % 3.14159", "'%s-%d' % ('a', 7)", "python.list(python.range(3))",
                   "math.factorial(20)", "math.comb(10, 3)", "math.perm(5)", "math.prod([2, 3, 4])",
                   "[x * y for x in [1, 2] for y in [3]]", "2**1000 % 97", "range(0, 10, 3)"]
    body = "\n  ".join(f'<link name="l{i}" value="${{{escape(e)}}}"/>' for i, e in enumerate(expressions))
    text, said = _expand(tmp_path, body)
    assert said == [] and text is not None
    import math

    for i, e in enumerate(expressions):
        value = eval(e.replace("python.", ""), {"math": math, "range": range})  # what xacro prints
        assert f'<link name="l{i}" value="{value}"/>' in text


def test_a_computed_or_too_wide_format_spec_is_refused() -> None:
    assert bounded_code("f'{1:>{10**9}}'") == "its format spec is computed"
    assert bounded_code("f'{1:>999999999}'") == "its format is wider than 10,000 characters"
    assert not isinstance(bounded_code("f'{1.5:>8.3f}'"), str)


MACRO_BOMB = """<xacro:macro name="twice" params="n">
    <xacro:if value="${n > 0}"><xacro:twice n="${n - 1}"/><xacro:twice n="${n - 1}"/></xacro:if>
  </xacro:macro>
  <xacro:twice n="22"/>"""


def test_an_expansion_that_runs_too_long_is_stopped_and_the_next_one_runs(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(xacro_limits, "MAX_SECONDS", 1.0)
    started = time.monotonic()
    text, said = _expand(tmp_path / "bomb", MACRO_BOMB)  # 2²² macro calls: minutes
    stopped = f"the expansion was stopped: it ran for more than 1 s{TAIL}"
    assert text is None and said == [("E0673", stopped, 1, 1)]
    assert time.monotonic() - started < 15
    time.sleep(0.2)  # nothing left pending in this thread
    text, said = _expand(tmp_path / "fine", '<link name="${2 * 21}"/>')
    assert said == [] and text is not None and '<link name="42"/>' in text


def _spinner(deadline: float) -> Callable[[], None]:
    """Python code that runs until `deadline`: each of its checks for a pending exception is
    inside it, so inside whatever `try` the caller puts around it."""
    def spin() -> None:
        while time.monotonic() < deadline:
            time.sleep(0.001)
    return spin


def test_the_watchdog_s_exception_passes_through_except_exception(monkeypatch: pytest.MonkeyPatch) -> None:
    """xacro reads a literal by trying int, float and bool in turn, each under `except
    Exception: pass`, and an expansion spends much of its time there: the exception must not
    end in it (it did, now and then, and the expansion ran on for many minutes)."""
    monkeypatch.setattr(xacro_limits, "MAX_SECONDS", 0.2)
    deadline = time.monotonic() + 10  # without the fix, the loop ends here: the test fails, not hangs
    spin = _spinner(deadline)
    with pytest.raises(ExpansionTooLong), watched():
        while time.monotonic() < deadline:
            try:  # noqa: SIM105 (as xacro writes it)
                spin()
            except Exception:
                pass
    assert time.monotonic() < deadline - 8


def test_an_exception_the_expansion_swallows_is_raised_again(monkeypatch: pytest.MonkeyPatch) -> None:
    """An exception raised while a destructor or a weakref callback runs is printed and dropped:
    the watchdog raises it again until the expansion has ended."""
    monkeypatch.setattr(xacro_limits, "MAX_SECONDS", 0.2)
    deadline = time.monotonic() + 10
    spin, swallowed = _spinner(deadline), 0
    with pytest.raises(ExpansionTooLong), watched():
        while True:
            try:
                spin()
                break
            except ExpansionTooLong:
                swallowed += 1
                if swallowed > 1:
                    raise
    assert swallowed == 2 and time.monotonic() < deadline - 8


def test_an_expansion_that_grows_the_process_too_much_is_stopped(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(xacro_limits, "MAX_MEMORY", 200 << 20)
    strings = "python.len([python.str(x) for x in python.range(10**7)])"  # about 600 MB
    text, said = _expand(tmp_path, f'<link name="${{{strings}}}"/>')
    stopped = f"the expansion was stopped: it took more than 200 MiB of memory{TAIL}"
    assert text is None and said == [("E0673", stopped, 1, 1)]
