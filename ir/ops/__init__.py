"""IR operations: frozen dataclasses that rewrite a Robot, with declared name effects.

Every op has a `kind` (derived from its class name and registered in `OPS`, the one
table that the IR printer and parser share), the `span` of the YAML that asked for
it, the `part` of the assembly it edits, `reads` (the names that must exist before
it runs), `effect` (how it changes the names, for `mpc check`) and `apply` (a pure
function Robot → Robot). An op whose `apply` is not written yet says so through
`SUPPORTED`, and compiling a definition that needs it is an error, not a crash.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mpc.ir.names import Names
from mpc.ir.ops.base import OPS, ROOT, Effects, Op, Phase, Ref

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
    "Phase",
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
