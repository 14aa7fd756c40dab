"""Diagnostics → text: human (source line and caret), gcc one-line, JSON.

The human renderer reads the source lines it shows on demand; it never fails on a
file it cannot read (it then prints the header line alone).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager, redirect_stdout

from mpc.core.diagnostics import Diagnostic, Severity
from mpc.core.span import Span, source_line

MAX_SHOWN = 50


def _excerpt(span: Span) -> list[str]:
    line = source_line(span.file, span.line)
    if line is None:
        return []
    text = line.expandtabs(1)
    width = len(str(span.line))
    end = span.end_col if span.end_line == span.line and span.end_col > span.col else span.col + 1
    end = min(max(end, span.col + 1), max(len(text) + 1, span.col + 1))
    caret = " " * (span.col - 1) + "^" * (end - span.col)
    return [f" {span.line} | {text}", f" {' ' * width} | {caret}"]


def human(diagnostics: Iterable[Diagnostic]) -> str:
    """rustc-like: `file:line:col: error[E0101]: message`, the line, a caret, notes."""
    out: list[str] = []
    diags = list(diagnostics)
    for d in diags[:MAX_SHOWN]:
        out.append(f"{d.span}: {d.severity.value}[{d.code}]: {d.message}")
        out.extend(_excerpt(d.span))
        for span, text in d.notes:
            out.append(f"  note: {span}: {text}" if span else f"  note: {text}")
        if d.hint:
            out.append(f"  hint: {d.hint}")
    if len(diags) > MAX_SHOWN:
        out.append(f"… and {len(diags) - MAX_SHOWN} more")
    return "\n".join(out)


def gcc(diagnostics: Iterable[Diagnostic]) -> str:
    """One line each, `file:line:col: severity: message [code]`, for editor matchers."""
    return "\n".join(
        f"{d.span}: {d.severity.value}: {d.message} [{d.code}]" for d in diagnostics
    )


def as_json(diagnostics: Iterable[Diagnostic]) -> str:
    """A JSON list of objects with code, severity, message, span, notes and hint."""
    import json  # only for --format json: `mpc check` would import it for nothing

    def span(s: Span | None) -> dict[str, object] | None:
        if s is None:
            return None
        return {"file": s.file, "line": s.line, "col": s.col,
                "end_line": s.end_line, "end_col": s.end_col}

    return json.dumps(
        [
            {
                "code": d.code,
                "severity": d.severity.value,
                "message": d.message,
                "span": span(d.span),
                "notes": [{"span": span(s), "message": t} for s, t in d.notes],
                "hint": d.hint,
            }
            for d in diagnostics
        ],
        indent=2,
    )


def summary(diagnostics: list[Diagnostic]) -> str:
    errors = sum(d.severity is Severity.ERROR for d in diagnostics)
    warnings = sum(d.severity is Severity.WARNING for d in diagnostics)
    parts = []
    if errors:
        parts.append(f"{errors} error{'s' * (errors != 1)}")
    if warnings:
        parts.append(f"{warnings} warning{'s' * (warnings != 1)}")
    return ", ".join(parts)


# With `--format json` the diagnostics of a whole command are one JSON document on stdout; what
# the command prints besides goes to stderr meanwhile (see `json_document`).
_collected: list[Diagnostic] | None = None


def print_diagnostics(diagnostics: Iterable[Diagnostic], fmt: str) -> None:
    """Diagnostics as `fmt` (human, gcc or json) on stderr, or into the open JSON document."""
    diags = list(diagnostics)
    if fmt == "json" and _collected is not None:
        _collected.extend(diags)
    elif fmt == "json":
        print(as_json(diags), file=sys.stderr)
    elif diags:
        print((gcc if fmt == "gcc" else human)(diags), file=sys.stderr)


@contextmanager
def json_document() -> Iterator[None]:
    """Collect what `print_diagnostics` is given as json into one document, printed on stdout
    at the end (an empty list when there was none); meanwhile stdout goes to stderr."""
    global _collected
    stdout, _collected = sys.stdout, []
    try:
        with redirect_stdout(sys.stderr):
            yield
    finally:
        collected, _collected = _collected, None
        print(as_json(collected), file=stdout)
