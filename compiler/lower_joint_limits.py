"""A `joint_limits` export_config entry (AST) → ir.JointLimitsExport: its joint selection checked.

The joints it names are checked against the robot when it is written (backends/joint_limits.py);
lowering reads no model.
"""

from __future__ import annotations

from collections.abc import Collection
from typing import Any

from mpc.compiler.lower_context import LowerContext
from mpc.core.diagnostics import did_you_mean
from mpc.ir.program import JOINT_SELECTIONS, Export, JointLimitsExport


def lower_joint_limits(ctx: LowerContext, entry: Any, submodels: Collection[str], submodel: str,
                       inherited: bool) -> list[Export]:
    """A joint_limits entry of the export_config whose submodels are `submodels`, written with
    the submodel `submodel` (or the model). An entry a submodel inherits reports nothing: the
    model's own use of it did."""
    joints = tuple(entry.joints)
    # `joints: name` (a string, not a list) of a submodel lists that submodel's joints.
    as_string = isinstance(entry.data_at("joints"), str)
    if len(joints) == 1 and as_string and joints[0] in submodels:
        return [JointLimitsExport(span=entry.span, file_name=entry.file_name, joints_of=joints[0],
                                  submodel=submodel)]
    if len(joints) == 1 and as_string and joints[0].isupper() and joints[0] not in JOINT_SELECTIONS:
        if not inherited:
            ctx.sink.error(entry.value_span("joints"), "E0524", f"joints: '{joints[0]}' is none of "
                           f"{', '.join(JOINT_SELECTIONS)} and names no submodel of this export_config"
                           f"{did_you_mean(joints[0], set(JOINT_SELECTIONS) | set(submodels))}")
        return []
    return [JointLimitsExport(span=entry.span, joints=joints, file_name=entry.file_name, submodel=submodel)]
