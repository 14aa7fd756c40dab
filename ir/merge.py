"""Robot + joints to merge away → the robot without them; what names them follows.

Each joint goes as `RemoveJoint` removes it (its child link joins the parent link: mass
properties combined, shapes and child joints re-expressed). Beyond that op, the data that
named a removed joint or a merged link is kept right here: motors and pose entries of a
removed joint go, sensors on a merged link move to the link it merged into, loop-closure
joints are re-expressed between the surviving links, and submechanisms lose the removed
joints (a submechanism left without joints goes). Used by the submodel and kccd exports.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace
from typing import Any

import numpy as np

from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir import refs as declared
from mpc.ir.kinematics import links_in_root, matrix_pose, pose_matrix
from mpc.ir.ops import Effects
from mpc.ir.ops.joints import RemoveJoint
from mpc.ir.robot import Pose, Robot
from mpc.ir.tree import depth_first


def merge_joints(robot: Robot, names: Iterable[str], sink: Sink, span: Span) -> Robot | None:
    """`robot` without the joints `names` (each must be a joint of it); None after an error
    (a kept joint that mimics a removed one)."""
    gone = set(names)
    if not gone:
        return robot
    # Leaves first, so that each removal re-expresses only what is still there; a joint that
    # mimics another goes before it, or RemoveJoint would refuse the other.
    order = [j.name for j, _ in depth_first(robot) if j is not None and j.name in gone][::-1]
    order.sort(key=lambda n: robot.joints[n].mimic is None)
    into = {robot.joints[n].child: robot.joints[n].parent for n in gone}
    before = len(sink.diagnostics)
    merged = robot
    for name in order:
        op = RemoveJoint(span=span, joint=name)
        merged = op.apply(merged, Effects(sink, op))
        if len(sink.diagnostics) > before:
            return None

    def survivor(link: str) -> str:
        while link in into:
            link = into[link]
        return link

    X_R = links_in_root(robot)

    def moved(link: str, pose: Pose | None) -> Pose:
        """A pose given in `link`, expressed in the link it merged into."""
        return matrix_pose(np.linalg.inv(X_R[survivor(link)]) @ X_R[link] @ pose_matrix(pose))

    sensors: dict[str, Any] = {}
    for name, sensor in merged.sensors.items():
        if sensor.joint in gone:
            sink.warning(span, "W0521", f"sensor '{name}' is on joint '{sensor.joint}', which is "
                         "merged away; it is left out")
            continue
        if sensor.link is not None and sensor.link in into:
            if sensor.orientation_offset is not None and len(sensor.orientation_offset) != 3:
                sink.warning(span, "W0521", f"sensor '{name}' is on link '{sensor.link}', which is "
                             "merged away, and its orientation_offset is not rpy; it is left out")
                continue
            pose = moved(sensor.link, Pose(sensor.position_offset or (0.0, 0.0, 0.0),
                                           tuple(sensor.orientation_offset or (0.0, 0.0, 0.0))))  # type: ignore[arg-type]
            sensor = replace(sensor, link=survivor(sensor.link), position_offset=pose.xyz,
                             orientation_offset=pose.rpy)
        if sensor.targets:
            sensor = replace(sensor, targets=tuple(dict.fromkeys(
                survivor(t) if t in into else t for t in sensor.targets if t not in gone)))
        sensors[name] = sensor
    cut_joints = {}
    for name, cut in merged.cut_joints.items():
        if cut.parent in into or cut.child in into:
            # X_P'C' = X_P'P · X_PC · X_CC', P' and C' the links P and C merged into.
            X_PC = pose_matrix(moved(cut.parent, None)) @ pose_matrix(cut.origin) \
                @ np.linalg.inv(pose_matrix(moved(cut.child, None)))
            cut = replace(cut, parent=survivor(cut.parent), child=survivor(cut.child),
                          origin=matrix_pose(X_PC))
        cut_joints[name] = cut
    def removed(kind: str, name: str) -> bool:
        return kind == "joint" and name in gone

    def kept(kind: str, name: str) -> bool:
        return not removed(kind, name)

    submechanisms = [declared.pruned(sm, removed, "definition") for sm in merged.submechanisms]
    return replace(
        merged,
        motors={n: m for n, m in merged.motors.items() if declared.names_only(m, kept)},
        poses={n: {j: v for j, v in p.items() if j not in gone} for n, p in merged.poses.items()},
        sensors=sensors, cut_joints=cut_joints,
        # A submechanism left without joints goes.
        submechanisms=tuple(sm for sm in submechanisms
                            if any(ref.kinds == ("joint",) for ref, _, _ in declared.refs(sm))))
