"""A floating base: the robot hung from a new root `world` by a `floating` joint.

URDF readers (urdfdom, Pinocchio) make such a joint a free flyer; MJCF makes it a
freejoint; an SDF model is free anyway, so the SDF writer leaves the joint out.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import replace

from mpc.ir.robot import Joint, Link, Pose, Robot

WORLD = "world"
JOINT = "floating_base"
FLOATING_HINT = ("leave out add_floating_base where the robot has a base joint of its own, or rename "
                 "that element (name editing)")


def clash(links: Collection[str], joints: Collection[str]) -> str | None:
    """What of a robot with these names keeps it from getting a floating base (E0505), or None."""
    taken = [f"a {kind} '{name}'" for kind, name, names in (("link", WORLD, links), ("joint", JOINT, joints))
             if name in names]
    if not taken:
        return None
    return (f"add_floating_base needs the names '{WORLD}' and '{JOINT}', but the robot has "
            f"{' and '.join(taken)} already")


def with_floating_base(robot: Robot) -> Robot | None:
    """`robot` below a `world` link through joint `floating_base`; None when the names are taken."""
    if clash(robot.links, robot.joints):
        return None
    joint = Joint(name=JOINT, type="floating", parent=WORLD, child=robot.root, origin=Pose())
    return replace(robot, root=WORLD, links={WORLD: Link(name=WORLD), **robot.links},
                   joints={JOINT: joint, **robot.joints})
