"""IR operations: frozen dataclasses that rewrite a Robot, with declared name effects.

Every op has a `kind` (derived from its class name and registered in `OPS`, the one
table that the IR printer and parser share), the `span` of the YAML that asked for
it, `reads` (names that must exist before it runs), `effect` (how it changes the
set of names) and `apply` (a pure function Robot → Robot).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import ClassVar

from mpc.ir.robot import Robot
from mpc.ir.span import Span

OPS: dict[str, type[Op]] = {}


@dataclass(frozen=True, slots=True)
class Names:
    """The names of a robot, as far as symbolic checks need them."""

    links: frozenset[str]
    joints: frozenset[str]

    @classmethod
    def of(cls, robot: Robot) -> Names:
        return cls(frozenset(robot.links), frozenset(robot.joints))


# Ops are not slotted: `slots=True` makes the dataclass decorator build a second class,
# after `__init_subclass__` has already registered the first one in OPS.
@dataclass(frozen=True, kw_only=True)
class Op:
    """Base of every IR operation. span: the YAML that asked for this op."""

    kind: ClassVar[str] = "op"
    span: Span

    def __init_subclass__(cls) -> None:
        cls.kind = re.sub(r"(?<!^)(?=[A-Z])", "_", cls.__name__).lower()
        OPS[cls.kind] = cls

    def reads(self) -> frozenset[str]:
        """Link and joint names that must exist when the op runs."""
        return frozenset()

    def effect(self, names: Names) -> Names:
        """The names after the op, computed from the names before it."""
        return names

    def apply(self, robot: Robot) -> Robot:
        raise NotImplementedError


from mpc.ir.ops.robot import SetRobotName  # noqa: E402  (registers itself in OPS)

__all__ = ["OPS", "Names", "Op", "SetRobotName"]
