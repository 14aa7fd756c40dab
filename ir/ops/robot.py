"""Ops on the robot as a whole."""

from __future__ import annotations

from dataclasses import replace

from mpc.core.record import record
from mpc.ir.ops.base import Effects, Op, Phase
from mpc.ir.robot import Robot


@record(kw_only=True)
class SetRobotName(Op):
    """Name the robot `name` (the `robotname` of the definition)."""

    PHASE = Phase.ROBOT_NAME

    name: str

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        return robot if robot.name == self.name else replace(robot, name=self.name)
