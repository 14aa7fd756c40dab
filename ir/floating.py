"""A floating base: the robot hung from a new root `world` by a `floating` joint.

URDF readers (urdfdom, Pinocchio) make such a joint a free flyer; MJCF makes it a
freejoint; an SDF model is free anyway, so the SDF writer leaves the joint out.
"""

from __future__ import annotations

from dataclasses import replace

from mpc.ir.robot import Joint, Link, Pose, Robot

WORLD = "world"
JOINT = "floating_base"


def with_floating_base(robot: Robot) -> Robot | None:
    """`robot` below a `world` link through joint `floating_base`; None when the names are taken."""
    if WORLD in robot.links or JOINT in robot.joints:
        return None
    joint = Joint(name=JOINT, type="floating", parent=WORLD, child=robot.root, origin=Pose())
    return replace(robot, root=WORLD, links={WORLD: Link(name=WORLD), **robot.links},
                   joints={JOINT: joint, **robot.joints})
