"""IR operations: frozen dataclasses that rewrite a Robot, with declared name effects.

Every op has a `kind` (derived from its class name and registered in `OPS`, the one
table that the IR printer and parser share), the `span` of the YAML that asked for
it, the `part` of the assembly it edits, `reads` (the names that must exist before
it runs), `effect` (how it changes the names, for `mpc check`) and `apply` (a pure
function Robot → Robot). An op whose `apply` is not written yet says so through
`SUPPORTED`, and compiling a definition that needs it is an error, not a crash.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import field
from typing import TYPE_CHECKING, Any, ClassVar

from mpc.compiler.diagnostics import Sink
from mpc.ir.names import Kind, Names
from mpc.ir.record import record
from mpc.ir.robot import Robot
from mpc.ir.span import Span

OPS: dict[str, type[Op]] = {}
ROOT = "root"


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
    span: Span
    part: str = ROOT
    spans: Mapping[str, Span] = field(default_factory=dict)

    def __init_subclass__(cls) -> None:
        cls.kind = re.sub(r"(?<!^)(?=[A-Z])", "_", cls.__name__).lower()
        OPS[cls.kind] = cls

    @classmethod
    def what(cls) -> str:
        return cls.WHAT or cls.kind.replace("_", " ")

    def span_of(self, field: str) -> Span:
        """The span of one of the op's fields, else of the op."""
        return self.spans.get(field, self.span)

    def reads(self) -> tuple[Ref, ...]:
        """Names that must exist when the op runs."""
        return ()

    def effect(self, names: Names, effects: Effects) -> Names:
        """The names after the op, computed from the names before it."""
        return names

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The robot after the op; problems only the values reveal go to `effects`."""
        raise NotImplementedError


# The op classes live in the modules below and register in OPS when their module is imported.
# A module is imported when one of its names is first asked for (`from mpc.ir.ops import AddFrame`,
# `ops.AddFrame`), so that `mpc check` imports only the ops a definition uses; `import_all` imports
# every one (the IR text printer and parser know every op).
_MODULES = {
    "annotate": ("AddAnnotations", "AddPose", "AddSensor", "AddSubmechanism", "AutoBitmask",
                 "CompleteSubmechanisms", "EditCollisions", "EditMaterial", "EditVisuals",
                 "SubmechanismsFile"),
    "assembly": ("Attach", "EditNames", "LoadModel", "Mirror", "RemoveBeyond", "TakeLeaf"),
    "frames": ("AddFrame", "AnnotateLinks", "EstimateMissingComs", "EstimateMissingInertia", "MakeRoot",
               "ReparentLink", "TransformFrame", "TransformLink"),
    "joints": ("AddCutJoint", "EditJoint", "JointDefaults", "MoveJointAxisToIntersection", "RemoveJoint",
               "ReplaceJointTypes", "SetMotor"),
    "meshes": ("ApplyScale", "ReduceMeshes"),
    "robot": ("SetRobotName",),
}
_MODULE_OF = {name: module for module, names in _MODULES.items() for name in names}

if TYPE_CHECKING:
    from mpc.ir.ops.annotate import (
        AddAnnotations,
        AddPose,
        AddSensor,
        AddSubmechanism,
        AutoBitmask,
        CompleteSubmechanisms,
        EditCollisions,
        EditMaterial,
        EditVisuals,
        SubmechanismsFile,
    )
    from mpc.ir.ops.assembly import (
        Attach,
        EditNames,
        LoadModel,
        Mirror,
        RemoveBeyond,
        TakeLeaf,
    )
    from mpc.ir.ops.frames import (
        AddFrame,
        AnnotateLinks,
        EstimateMissingComs,
        EstimateMissingInertia,
        MakeRoot,
        ReparentLink,
        TransformFrame,
        TransformLink,
    )
    from mpc.ir.ops.joints import (
        AddCutJoint,
        EditJoint,
        JointDefaults,
        MoveJointAxisToIntersection,
        RemoveJoint,
        ReplaceJointTypes,
        SetMotor,
    )
    from mpc.ir.ops.meshes import ApplyScale, ReduceMeshes
    from mpc.ir.ops.robot import SetRobotName


def __getattr__(name: str) -> Any:
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'mpc.ir.ops' has no attribute '{name}'")
    # __import__ rather than importlib.import_module: it shows in `python -X importtime`.
    return getattr(__import__(f"{__name__}.{module}", fromlist=[name]), name)


def import_all() -> dict[str, type[Op]]:
    """OPS with every op in it."""
    for module in _MODULES:
        __import__(f"{__name__}.{module}")
    return OPS


__all__ = [
    "OPS",
    "ROOT",
    "AddAnnotations",
    "AddCutJoint",
    "AddFrame",
    "AddPose",
    "AddSensor",
    "AddSubmechanism",
    "AnnotateLinks",
    "ApplyScale",
    "Attach",
    "AutoBitmask",
    "CompleteSubmechanisms",
    "EditCollisions",
    "EditJoint",
    "EditMaterial",
    "EditNames",
    "EditVisuals",
    "Effects",
    "EstimateMissingComs",
    "EstimateMissingInertia",
    "JointDefaults",
    "LoadModel",
    "MakeRoot",
    "Mirror",
    "MoveJointAxisToIntersection",
    "Names",
    "Op",
    "ReduceMeshes",
    "Ref",
    "RemoveBeyond",
    "RemoveJoint",
    "ReparentLink",
    "ReplaceJointTypes",
    "SetMotor",
    "SetRobotName",
    "SubmechanismsFile",
    "TakeLeaf",
    "TransformFrame",
    "TransformLink",
    "import_all",
]
