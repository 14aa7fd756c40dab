"""Which links of the MJCF may collide: the collision bitmasks, or the URDF rule without them.

MuJoCo lets two collision geoms collide when (contype1 & conaffinity2) | (contype2 &
conaffinity1) ≠ 0, their bodies are not welded together (one rigid body: MuJoCo never
collides it with itself), the pair is not in `<contact><exclude>`, and, unless the
`filterparent` flag is disabled, neither body's rigid body is the other's parent. The MJCF
disables `filterparent` and says everything itself:

- With bitmasks (any collision has one: `auto_bitmask`, a SMURF's): contype = conaffinity =
  the bitmask, so two collisions collide exactly when their bitmasks share a bit (ir/bitmask.py's
  rule; `auto_bitmask` never lets a link collide with its parent). No exclusions.
- Without: every collision geom has MuJoCo's default (1), and each two rigid bodies joined by a
  joint are excluded (every pair of their links that have collisions): the URDF convention that
  links joined by a joint do not collide (their shapes meet at the joint). The root's rigid body
  is welded to the world, and excluded from its children's too.

A rigid body is a link and the links welded to it by fixed joints; the world's holds the root
(unless a floating joint hangs it from `world`).
"""

from __future__ import annotations

from itertools import product

from mpc.ir.robot import Robot
from mpc.ir.tree import depth_first

__all__ = ["excluded_pairs", "rigid_bodies", "uses_bitmasks"]


def uses_bitmasks(robot: Robot) -> bool:
    """Whether any collision of the robot has a bitmask."""
    return any(c.bitmask is not None for lk in robot.links.values() for c in lk.collisions)


def rigid_bodies(robot: Robot) -> dict[str, str]:
    """Each link's rigid body, named by its top link (the links welded together by fixed
    joints move as one; MuJoCo's `body_weldid`)."""
    group: dict[str, str] = {}
    for joint, link in depth_first(robot):
        group[link] = group[joint.parent] if joint is not None and joint.type == "fixed" else link
    return group


def excluded_pairs(robot: Robot) -> list[tuple[str, str]]:
    """The `<exclude body1 body2>` pairs (link names), in the joints' depth-first order: none
    with bitmasks; else the links with collisions of each two rigid bodies a moving joint
    joins (see the module)."""
    if uses_bitmasks(robot):
        return []
    group = rigid_bodies(robot)
    members: dict[str, list[str]] = {}
    for _, link in depth_first(robot):
        if robot.links[link].collisions:
            members.setdefault(group[link], []).append(link)
    out: list[tuple[str, str]] = []
    for joint, _ in depth_first(robot):
        if joint is None or joint.type == "fixed":
            continue
        parents, children = members.get(group[joint.parent], []), members.get(group[joint.child], [])
        out.extend(product(parents, children))
    return out
