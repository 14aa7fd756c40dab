"""PassContext: what every pass (compiler/passes/) may use besides the program."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from mpc.core.diagnostics import Severity, Sink
from mpc.ir.names import Names
from mpc.ir.program import Input


def _unknown(_: Input) -> Names | None:
    return None


@dataclass
class PassContext:
    """What every pass may use: the diagnostics sink, the input models' names, and whether
    what compiling does not support yet is an error (compile) or a warning (check)."""

    sink: Sink
    input_names: Callable[[Input], Names | None] = field(default=_unknown)
    later: Severity = Severity.ERROR
