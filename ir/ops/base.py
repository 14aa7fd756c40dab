"""The base of the IR's operations: `Op`, its `Phase`, the `Ref`s it reads, the `Effects` it
reports through, and `OPS`, where every op class registers. The op classes are in the modules
beside this one (ir/ops/__init__.py describes them and imports them on demand).
"""


from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import field
from enum import IntEnum
from typing import ClassVar

from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.names import Kind, Names
from mpc.ir.refs import refs as declared_refs
from mpc.ir.robot import Robot

OPS: dict[str, type[Op]] = {}
ROOT = "root"


class Phase(IntEnum):
    """Where an op runs in the language's order (specs/passes.md "Order of operations").

    The first six are the steps of one part of the assembly, which the parts take depth first
    (a part's own steps, then each child part and its attaching); the rest edit the assembled
    robot, one section after another. Ops of one phase keep the order they are written in.
    """

    LOAD = 0
    NAMES = 1
    REMOVE_BEYOND = 2
    TAKE_LEAF = 3
    MIRROR = 4
    ATTACH = 5
    ROBOT_NAME = 10
    MATERIALS = 11
    FRAMES = 12
    JOINTS = 13
    COLLISIONS = 14
    VISUALS = 15
    SUBMECHANISMS = 16
    SENSORS = 17
    POSES = 18
    ANNOTATIONS = 19
    MESHES = 20

    @property
    def assembly(self) -> bool:
        """Whether ops of this phase build a part of the assembly (else they edit the robot)."""
        return self <= Phase.ATTACH


@record(slots=True)
class Ref:
    """A name an op needs: its kind, the name, and the op field that holds it (for spans)."""

    kind: Kind
    name: str
    field: str = ""
    written: str = ""  # the name as the user wrote it, when an edit changed it


class Effects:
    """What an op's `effect` may report, at the op's span or one of its fields.

    later_is_error: whether a part of the language that `apply` does not support yet is
    an error (compiling) or a warning (`mpc check`).
    """

    def __init__(self, sink: Sink, op: Op, later_is_error: bool = True) -> None:
        self.sink, self.op, self.later_is_error = sink, op, later_is_error

    def error(self, code: str, message: str, field: str = "") -> None:
        self.sink.error(self.op.span_of(field), code, message)

    def warning(self, code: str, message: str, field: str = "") -> None:
        self.sink.warning(self.op.span_of(field), code, message)

    def unsupported(self, what: str, field: str = "") -> None:
        if self.later_is_error:
            self.sink.error(self.op.span_of(field), "E0202", f"{what} is not supported yet")
        else:
            self.sink.warning(self.op.span_of(field), "W0202",
                              f"{what} is not supported by `mpc compile` yet")


# Ops are not slotted: `slots=True` makes the dataclass decorator build a second class,
# after `__init_subclass__` has already registered the first one in OPS.
@record(kw_only=True)
class Op:
    """Base of every IR operation. span: the YAML that asked for this op."""

    kind: ClassVar[str] = "op"
    SUPPORTED: ClassVar[bool] = True
    WHAT: ClassVar[str] = ""  # how messages name the op; default: its kind in words
    EFFECT_NEEDS_READS: ClassVar[bool] = True  # False: `effect` is sound even if a read is missing
    PHASE: ClassVar[Phase]  # every op class declares it (tests/compiler/test_passes.py checks)
    span: Span
    part: str = ROOT
    spans: Mapping[str, Span] = field(default_factory=dict)

    def __init_subclass__(cls) -> None:
        cls.kind = re.sub(r"(?<!^)(?=[A-Z])", "_", cls.__name__).lower()
        OPS[cls.kind] = cls

    @classmethod
    def what(cls) -> str:
        return cls.WHAT or cls.kind.replace("_", " ")

    def phase(self) -> Phase:
        """Where the op runs in the language's order (an op whose fields decide says so)."""
        return self.PHASE

    def parts(self) -> tuple[str, ...]:
        """The parts of the assembly the op reads or changes."""
        return (self.part,)

    def span_of(self, field: str) -> Span:
        """The span of one of the op's fields (`links/2`, else `links`), else of the op."""
        while field:
            if field in self.spans:
                return self.spans[field]
            field = field.rpartition("/")[0]
        return self.span

    def reads(self) -> tuple[Ref, ...]:
        """Names that must exist when the op runs: its fields typed as references (ir/refs.py),
        in the order of the fields. An op whose reads depend on other fields writes its own."""
        return tuple(Ref(declared.kinds[0], name, path)  # type: ignore[arg-type]
                     for declared, name, path in declared_refs(self) if not declared.defines)

    def effect(self, names: Names, effects: Effects) -> Names:
        """The names after the op, computed from the names before it."""
        return names

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The robot after the op; problems only the values reveal go to `effects`."""
        raise NotImplementedError
