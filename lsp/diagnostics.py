"""mpc's Diagnostics → LSP diagnostics of one buffer: range, severity, code, hint, related notes.

A diagnostic located in another file is shown on the buffer's line that reads that file (an
input model's `basefile` or `derived_base`), else at the top of the buffer (a defaults file),
with the other file's place as related information. What this does
not do: decide what is checked (analysis.py).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

from mpc.core.diagnostics import Diagnostic, Severity
from mpc.core.span import Span, source_line
from mpc.lsp import structures as lsp
from mpc.lsp.text import Lines

_SEVERITY = {Severity.ERROR: lsp.Severity.ERROR, Severity.WARNING: lsp.Severity.WARNING,
             Severity.NOTE: lsp.Severity.INFORMATION}
DID_YOU_MEAN = re.compile(r"did you mean '([^']+)'\?")


def uri_of(file: str) -> str:
    return Path(os.path.abspath(file)).as_uri()


def location(span: Span, lines: Lines | None = None) -> lsp.Location:
    """The place of a span; `lines`: its file's text when it is the buffer, else read from disk."""
    if lines is None:
        text = source_line(span.file, span.line) or ""
        lines = _OneLine(span.line, text)
    return lsp.Location(uri=uri_of(span.file), range=lines.range(span))


class _OneLine(Lines):
    """The one line of a file on disk that a span needs."""

    def __init__(self, number: int, text: str) -> None:
        self.lines = [""] * (number - 1) + [text]


def convert(diagnostics: list[Diagnostic], path: Path, lines: Lines,
            readers: Mapping[str, Span] | None = None) -> list[lsp.Diagnostic]:
    """The LSP diagnostics of the buffer of `path`; `readers`: the buffer's span that reads each
    other file (by absolute path), where that file's diagnostics are shown."""
    out = []
    here = os.path.abspath(path)
    for d in diagnostics:
        related = [lsp.DiagnosticRelatedInformation(location=location(span, lines if os.path.abspath(
            span.file) == here else None), message=note) for span, note in d.notes if span is not None]
        message = d.message + "".join(f"\n{note}" for span, note in d.notes if span is None)
        if d.hint:
            message += f"\nhint: {d.hint}"
        if os.path.abspath(d.span.file) == here:
            where = lines.range(d.span)
        else:
            related.insert(0, lsp.DiagnosticRelatedInformation(location=location(d.span), message=d.message))
            message = f"{os.path.basename(d.span.file)}:{d.span.line}: {message}"
            reader = (readers or {}).get(os.path.abspath(d.span.file))
            where = lines.range(reader) if reader is not None else lsp.Range(
                start=lsp.Position(line=0, character=0), end=lsp.Position(line=0, character=0))
        diagnostic = lsp.Diagnostic(range=where, message=message, severity=_SEVERITY[d.severity], code=d.code,
                                    source="mpc")
        if related:
            diagnostic["relatedInformation"] = related
        out.append(diagnostic)
    return out
