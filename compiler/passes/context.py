"""PassContext: what every pass (compiler/passes/) may use besides the program."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field

from mpc.core.diagnostics import Severity, Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.names import Names
from mpc.ir.program import Input


def _unknown(_: Input) -> Names | None:
    return None


def _nowhere(_: Input, kind: str, name: str) -> Span | None:
    return None


@record(frozen=False)
class PassContext:
    """What every pass may use: the diagnostics sink, the input models' names, and whether
    what compiling does not support yet is an error (compile) or a warning (check)."""

    sink: Sink
    input_names: Callable[[Input], Names | None] = field(default=_unknown)
    later: Severity = Severity.ERROR
    # where an input model holds one of its names (kind, name), when it can tell
    name_span: Callable[[Input, str, str], Span | None] = field(default=_nowhere)
