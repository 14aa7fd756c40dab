"""ir.Robot → a ROCK joint-limits file (YAML), for the joints an export selects.

Format (Phobos's): `{limits: {names: [...], elements: [{max: {position, speed, effort},
min: {position}}]}}`. Fixed joints are never listed; a missing limit is written as 0. A
continuous joint has no position limit: its min and max position are `.nan`, which ROCK's
typelib YAML reads as NaN, base's "unset" (`base::JointLimitRange` checks a position only
against a bound that `hasPosition()`); 0..0 would read as a locked joint.
Selections: ALL (every movable joint), ACTIVE and INDEPENDENT (the submechanisms'
`jointnames_active` / `jointnames_independent`), ABSTRACT (the movable joints of the
abstract model, ir/submodel.py), ACTUATED (joints with a motor), or a list of joint names;
`joints: <submodel>` is ALL of that submodel (the driver passes it in). Written as
block-style YAML with sorted keys (as Phobos's YAML writer did), so it diffs cleanly.
"""

from __future__ import annotations

from pathlib import Path

from mpc.backends.xml import write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.ir.program import JointLimitsExport
from mpc.ir.robot import Robot
from mpc.ir.tree import depth_first

UNSET = float("nan")  # base::unset<double>(): no bound


def select(robot: Robot, export: JointLimitsExport, sink: Sink) -> list[str]:
    """The joints the export lists, in the tree's canonical order."""
    movable = [j.name for j, _ in depth_first(robot) if j is not None and j.type != "fixed"]
    if export.joints == ("ALL",):
        return movable
    if export.joints in (("ACTIVE",), ("INDEPENDENT",), ("ABSTRACT",)):
        if not robot.submechanisms:
            sink.warning(export.span, "W0503", f"joints: {export.joints[0]} needs submechanisms; this "
                         "model has none, so every movable joint is listed (as Phobos does)")
            return movable
        if export.joints == ("ABSTRACT",):
            from mpc.ir.submodel import abstract_joints

            chosen = abstract_joints(robot)
        else:
            key = f"jointnames_{export.joints[0].lower()}"
            chosen = {str(j) for sm in robot.submechanisms for j in sm.definition.get(key, ())}
        return [j for j in movable if j in chosen]
    if export.joints == ("ACTUATED",):
        driven = {m.joint for m in robot.motors.values()}
        return [j for j in movable if j in driven]
    listed = []
    for name in export.joints:
        joint = robot.joints.get(name)
        if joint is None or joint.type == "fixed":
            sink.error(export.span, "E0310", f"joint_limits lists '{name}', which is not a movable "
                       "joint of the model")
        else:
            listed.append(name)
    return listed


def to_yaml(robot: Robot, names: list[str]) -> str:
    elements = []
    for name in names:
        joint = robot.joints[name]
        lim = joint.limit
        if joint.type == "continuous":  # no position limit: unset, as ROCK's base::JointState says it
            lower = upper = UNSET
        else:
            lower = lim.lower if lim and lim.lower is not None else 0.0
            upper = lim.upper if lim and lim.upper is not None else 0.0
        elements.append({"max": {"position": upper, "speed": lim.velocity if lim and lim.velocity else 0.0,
                                 "effort": lim.effort if lim and lim.effort else 0.0},
                         "min": {"position": lower}})
    from mpc.backends.smurf import dumps

    return dumps({"limits": {"names": names, "elements": elements}})


def emit(robot: Robot, export: JointLimitsExport, out: Path, sink: Sink) -> None:
    """Write `<file_name>` in the export's root folder."""
    names = select(robot, export, sink)
    write_path(confined(out, export.file_name), to_yaml(robot, names))
