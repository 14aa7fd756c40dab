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

# The op catalogue: each op module and the op classes it defines, the one list of the ops.
# An op class registers in OPS when its module is imported; a module is imported when one of
# its names is first asked for (`from mpc.ir.ops import AddFrame`, `ops.AddFrame`), so that
# `mpc check` imports only the ops a definition uses; `import_all` imports every one (the IR
# text printer and parser know every op). The lazy names, `import_all` and `__all__` derive
# from it; the imports under TYPE_CHECKING below repeat it for static tools (editors, type
# checkers), which cannot read a table, and tests/ir/test_op_catalogue.py holds the two equal
# and every op class defined in an op module listed.
CATALOGUE: dict[str, tuple[str, ...]] = {
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
_MODULE_OF = {name: module for module, names in CATALOGUE.items() for name in names}

if TYPE_CHECKING:  # the catalogue again, for static tools (`X as X`: a name this package exports)
    from mpc.ir.ops.annotate import AddAnnotations as AddAnnotations
    from mpc.ir.ops.annotate import AddPose as AddPose
    from mpc.ir.ops.annotate import AddSensor as AddSensor
    from mpc.ir.ops.annotate import AddSubmechanism as AddSubmechanism
    from mpc.ir.ops.annotate import AutoBitmask as AutoBitmask
    from mpc.ir.ops.annotate import CompleteSubmechanisms as CompleteSubmechanisms
    from mpc.ir.ops.annotate import EditCollisions as EditCollisions
    from mpc.ir.ops.annotate import EditMaterial as EditMaterial
    from mpc.ir.ops.annotate import EditVisuals as EditVisuals
    from mpc.ir.ops.annotate import SubmechanismsFile as SubmechanismsFile
    from mpc.ir.ops.assembly import Attach as Attach
    from mpc.ir.ops.assembly import EditNames as EditNames
    from mpc.ir.ops.assembly import LoadModel as LoadModel
    from mpc.ir.ops.assembly import Mirror as Mirror
    from mpc.ir.ops.assembly import RemoveBeyond as RemoveBeyond
    from mpc.ir.ops.assembly import TakeLeaf as TakeLeaf
    from mpc.ir.ops.frames import AddFrame as AddFrame
    from mpc.ir.ops.frames import AnnotateLinks as AnnotateLinks
    from mpc.ir.ops.frames import EstimateMissingComs as EstimateMissingComs
    from mpc.ir.ops.frames import EstimateMissingInertia as EstimateMissingInertia
    from mpc.ir.ops.frames import MakeRoot as MakeRoot
    from mpc.ir.ops.frames import ReparentLink as ReparentLink
    from mpc.ir.ops.frames import TransformFrame as TransformFrame
    from mpc.ir.ops.frames import TransformLink as TransformLink
    from mpc.ir.ops.joints import AddCutJoint as AddCutJoint
    from mpc.ir.ops.joints import EditJoint as EditJoint
    from mpc.ir.ops.joints import JointDefaults as JointDefaults
    from mpc.ir.ops.joints import MoveJointAxisToIntersection as MoveJointAxisToIntersection
    from mpc.ir.ops.joints import RemoveJoint as RemoveJoint
    from mpc.ir.ops.joints import ReplaceJointTypes as ReplaceJointTypes
    from mpc.ir.ops.joints import SetMotor as SetMotor
    from mpc.ir.ops.meshes import ApplyScale as ApplyScale
    from mpc.ir.ops.meshes import ReduceMeshes as ReduceMeshes
    from mpc.ir.ops.robot import SetRobotName as SetRobotName


def __getattr__(name: str) -> Any:
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'mpc.ir.ops' has no attribute '{name}'")
    # __import__ rather than importlib.import_module: it shows in `python -X importtime`.
    return getattr(__import__(f"{__name__}.{module}", fromlist=[name]), name)


def import_all() -> dict[str, type[Op]]:
    """OPS with every op in it."""
    for module in CATALOGUE:
        __import__(f"{__name__}.{module}")
    return OPS


__all__ = ["CATALOGUE", "OPS", "ROOT", "Effects", "Names", "Op", "Phase", "Ref", "import_all", *_MODULE_OF]
