"""Numbers of a robot value: set those that are zero but for rounding (`enforce_zero`)."""

from __future__ import annotations

import dataclasses
from typing import Any

EPSILON = 1e-12


def _zero(value: Any, eps: float) -> Any:
    if isinstance(value, float):
        return 0.0 if abs(value) < eps else value
    if isinstance(value, tuple):
        return tuple(_zero(v, eps) for v in value)
    if isinstance(value, dict):
        return {k: _zero(v, eps) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        changes = {f.name: _zero(getattr(value, f.name), eps) for f in dataclasses.fields(value)
                   if f.name not in ("span", "annotations", "extras", "fragments")}
        return dataclasses.replace(value, **changes)
    return value


def zero_small(robot: Any, eps: float = EPSILON) -> Any:
    """`robot` with every float closer to zero than `eps` replaced by 0.0 (annotations and
    opaque fragments are left as written)."""
    return _zero(robot, eps)
