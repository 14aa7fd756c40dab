"""Diagnostics: what went wrong, where, and what to do; collected, never raised.

Stages report into a `Sink` and go on (report and continue, as Drake's
DiagnosticPolicy does); the driver decides at phase boundaries whether to stop.
Exceptions are for compiler bugs only. The codes are listed in specs/diagnostics.md.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import field
from enum import Enum

from mpc.core.record import record
from mpc.core.span import Span


class Severity(Enum):
    """How bad a diagnostic is; `error` fails the build."""

    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


@record(slots=True)
class Diagnostic:
    """One finding.

    code: a stable identifier (E0101, W0500, …) that tests and users can rely on.
    message: one sentence naming the element and its kind.
    span: where; notes: further (span, text) pointers; hint: what to do about it.
    """

    severity: Severity
    code: str
    message: str
    span: Span
    notes: tuple[tuple[Span | None, str], ...] = ()
    hint: str | None = None


class FailFast(Exception):
    """Raised by a fail-fast sink on the first error (tests only)."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(f"{diagnostic.span}: {diagnostic.code}: {diagnostic.message}")
        self.diagnostic = diagnostic


@record(frozen=False)
class Sink:
    """Collects diagnostics.

    werror: warnings count as errors. fail_fast: raise FailFast on the first error.
    """

    werror: bool = False
    fail_fast: bool = False
    diagnostics: list[Diagnostic] = field(default_factory=list)

    def report(self, diagnostic: Diagnostic) -> None:
        if self.werror and diagnostic.severity is Severity.WARNING:
            diagnostic = Diagnostic(
                Severity.ERROR, diagnostic.code, diagnostic.message, diagnostic.span,
                diagnostic.notes, diagnostic.hint,
            )
        self.diagnostics.append(diagnostic)
        if self.fail_fast and diagnostic.severity is Severity.ERROR:
            raise FailFast(diagnostic)

    def error(self, span: Span, code: str, message: str, *,
              notes: tuple[tuple[Span | None, str], ...] = (), hint: str | None = None) -> None:
        self.report(Diagnostic(Severity.ERROR, code, message, span, notes, hint))

    def warning(self, span: Span, code: str, message: str, *,
                notes: tuple[tuple[Span | None, str], ...] = (), hint: str | None = None) -> None:
        self.report(Diagnostic(Severity.WARNING, code, message, span, notes, hint))

    def at(self, span: Span) -> LocatedSink:
        """A sink that lends `span` to helpers that know no location of their own."""
        return LocatedSink(self, span)

    @property
    def error_count(self) -> int:
        return sum(d.severity is Severity.ERROR for d in self.diagnostics)

    def has_errors(self) -> bool:
        return self.error_count > 0

    def __iter__(self) -> Iterator[Diagnostic]:
        return iter(self.diagnostics)


@record(frozen=False)
class LocatedSink:
    """A Sink bound to a span (MakePolicyForNode in Drake's terms)."""

    sink: Sink
    span: Span

    def error(self, code: str, message: str, *, hint: str | None = None) -> None:
        self.sink.error(self.span, code, message, hint=hint)

    def warning(self, code: str, message: str, *, hint: str | None = None) -> None:
        self.sink.warning(self.span, code, message, hint=hint)


def did_you_mean(word: str, candidates: list[str] | set[str] | frozenset[str]) -> str:
    """' (did you mean 'x'?)' for the nearest candidate, or '' when none is near."""
    from difflib import get_close_matches

    near = get_close_matches(word, sorted(candidates), n=1, cutoff=0.6)
    return f"; did you mean '{near[0]}'?" if near else ""
