"""A corpus of broken model definitions: one file per kind of mistake, each with the exact
diagnostics `mpc check` must report.

Every `broken/<kind>__invalid.yml` starts with one comment line per expected diagnostic

    # expect: E0201 2:3 unknown key 'robtname' in model; did you mean 'robotname'?
    # expect: E0404 arm.urdf:23:20 'xyz' of <origin> in joint 'j' must be 3 numbers, got '0 0'
    # hint: there are: lower, upper, base

(code, line:column in the fixture itself, or `<basename>:line:column` for a span in another
file such as a URDF or a defaults file, then the exact message; `{dir}` stands for the
absolute path of the broken/ folder). An optional `# hint:` line right after an expectation
asserts that diagnostic's hint as well. The set of all diagnostics `check_file` reports,
errors and warnings, must equal the expected set.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pytest

from mpc.cli.check import check_file
from mpc.compiler.options import Options
from mpc.core.diagnostics import Diagnostic, Severity, Sink

BROKEN = (Path(__file__).parent / "broken").resolve()
FIXTURES = sorted(BROKEN.glob("*__invalid.yml"))
MIN_FIXTURES = 45

_EXPECT = re.compile(r"# expect: (?P<code>[EW]\d{4}) (?:(?P<file>[^\s:]+):)?(?P<line>\d+):(?P<col>\d+) "
                     r"(?P<message>.+)")
_HINT = re.compile(r"# hint: (?P<hint>.+)")

Key = tuple[str, str, str]  # code, where ("line:col" or "file:line:col"), message

@dataclass
class Expected:
    key: Key
    hint: str | None = None


def kind(path: Path) -> str:
    return path.name.split("__invalid")[0]


def expectations(path: Path) -> list[Expected]:
    """The `# expect:` (and `# hint:`) lines at the top of a fixture."""
    out: list[Expected] = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if not line.startswith(("# expect", "# hint")):
            break
        line = line.replace("{dir}", str(BROKEN))
        if m := _EXPECT.fullmatch(line):
            where = f"{m['line']}:{m['col']}"
            out.append(Expected((m["code"], f"{m['file']}:{where}" if m["file"] else where, m["message"])))
        elif (h := _HINT.fullmatch(line)) and out and out[-1].hint is None:
            out[-1].hint = h["hint"]
        else:
            raise AssertionError(f"{path.name}:{number}: malformed expectation: {line!r}")
    return out


def where(d: Diagnostic, fixture: Path) -> str:
    at = f"{d.span.line}:{d.span.col}"
    file = Path(d.span.file).resolve()
    return at if file == fixture else f"{file.name}:{at}"


def check(fixture: Path) -> list[Diagnostic]:
    sink = Sink()
    check_file(fixture, sink, Options())
    return sink.diagnostics


def as_expect_line(key: Key) -> str:
    code, at, message = key
    return f"# expect: {code} {at} {message.replace(str(BROKEN), '{dir}')}"


@pytest.mark.parametrize("fixture", FIXTURES, ids=kind)
def test_broken_definition(fixture: Path) -> None:
    expected = expectations(fixture)
    assert expected, f"{fixture.name} has no '# expect:' line"
    diagnostics = check(fixture)
    actual = {(d.code, where(d, fixture), d.message): d for d in diagnostics}

    missing = [e.key for e in expected if e.key not in actual]
    unexpected = [k for k in actual if k not in {e.key for e in expected}]
    assert not missing and not unexpected, (
        f"{fixture.name}:\n  expected but not reported:\n    "
        + "\n    ".join(map(as_expect_line, missing))
        + "\n  reported but not expected:\n    " + "\n    ".join(map(as_expect_line, unexpected))
    )
    for d in diagnostics:
        wanted = Severity.WARNING if d.code.startswith("W") else Severity.ERROR
        assert d.severity is wanted, f"{d.code} is reported as a {d.severity.value}"
    for e in expected:
        if e.hint is not None:
            assert actual[e.key].hint == e.hint, f"hint of {e.key[0]} at {e.key[1]}"


@pytest.mark.parametrize("fixture", FIXTURES, ids=kind)
def test_no_diagnostic_reported_twice(fixture: Path) -> None:
    counts = Counter((d.code, where(d, fixture), d.message) for d in check(fixture))
    assert [k for k, n in counts.items() if n > 1] == []


def test_corpus_size() -> None:
    assert len(FIXTURES) >= MIN_FIXTURES, f"only {len(FIXTURES)} broken definitions"


def test_kinds_are_unique_and_well_named() -> None:
    kinds = [kind(f) for f in FIXTURES]
    assert all(re.fullmatch(r"[a-z0-9]+(?:_[a-z0-9]+)*", k) for k in kinds), kinds
    assert len({k.lower() for k in kinds}) == len(kinds)
    stray = [p.name for p in BROKEN.iterdir() if "__invalid" in p.name and p not in FIXTURES]
    assert stray == [], "fixtures must be named <kind>__invalid.yml"


def test_helper_definitions_are_valid() -> None:
    """The definitions that fixtures build on must themselves check cleanly."""
    sink = Sink()
    check_file(BROKEN / "parent_model.yml", sink, Options())
    assert sink.diagnostics == []
