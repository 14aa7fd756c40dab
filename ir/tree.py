"""Tree queries over a Robot: children, parents, depth-first order.

The reader guarantees the robot is a tree (one root, every other link the child
of exactly one joint); these helpers rely on that.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.span import Span
from mpc.ir.robot import Joint, Link, Robot


def child_joints(robot: Robot) -> dict[str, list[Joint]]:
    """Joints leaving each link, sorted by joint name (the order urdfdom uses)."""
    out: dict[str, list[Joint]] = {name: [] for name in robot.links}
    for joint in robot.joints.values():
        out.setdefault(joint.parent, []).append(joint)
    for joints in out.values():
        joints.sort(key=lambda j: j.name)
    return out


def parent_joint(robot: Robot) -> dict[str, Joint]:
    """The joint above each link; the root has none."""
    return {joint.child: joint for joint in robot.joints.values()}


def joints_up(robot: Robot, link: str) -> list[Joint]:
    """The joints from `link` up to the root, nearest first."""
    parents = parent_joint(robot)
    out = []
    while link in parents:
        out.append(parents[link])
        link = parents[link].parent
    return out


def movable_above(robot: Robot) -> dict[str, int]:
    """How many movable (not fixed) joints lie between each link and the root, top-down."""
    out: dict[str, int] = {}
    for joint, link in depth_first(robot):
        out[link] = 0 if joint is None else out[joint.parent] + (joint.type != "fixed")
    return out


def depth_first(robot: Robot) -> Iterator[tuple[Joint | None, str]]:
    """(joint leading to the link, link) from the root down, children by joint name."""
    children = child_joints(robot)
    stack: list[tuple[Joint | None, str]] = [(None, robot.root)]
    while stack:
        joint, link = stack.pop()
        yield joint, link
        stack.extend((j, j.child) for j in reversed(children.get(link, [])))


def check_tree(links: Mapping[str, Link], joints: Mapping[str, Joint], sink: Sink,
               span: Span, robot: str) -> str | None:
    """Report every way links and joints fail to form one tree; the root link, or None.

    Checks: each joint's parent and child exist, no link is the child of two joints,
    no joint connects a link to itself, exactly one link has no parent, and every
    link is reachable from it (otherwise there is a cycle).
    """
    ok = True
    parent_of: dict[str, Joint] = {}
    for joint in joints.values():
        where = joint.span or span
        for end in ("parent", "child"):
            link = getattr(joint, end)
            if link not in links:
                sink.error(where, "E0411", f"joint '{joint.name}' refers to unknown {end} link "
                           f"'{link}'{did_you_mean(link, set(links))}")
                ok = False
        if joint.parent == joint.child:
            sink.error(where, "E0413", f"joint '{joint.name}' connects link '{joint.child}' "
                       "to itself")
            ok = False
        if joint.child in parent_of:
            first = parent_of[joint.child]
            sink.error(where, "E0412", f"link '{joint.child}' is the child of two joints, "
                       f"'{first.name}' and '{joint.name}'; a URDF must be a tree",
                       notes=((first.span, f"joint '{first.name}' is defined here"),))
            ok = False
        else:
            parent_of[joint.child] = joint
    if not ok:
        return None
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        if not roots:
            sink.error(span, "E0413", f"robot '{robot}' has no root link: its joints form a cycle")
        else:
            notes = tuple((links[r].span, f"link '{r}' has no parent joint") for r in roots)
            sink.error(span, "E0414", f"robot '{robot}' has {len(roots)} root links "
                       f"({', '.join(roots)}); a URDF must be one tree", notes=notes)
        return None
    children: dict[str, list[str]] = {}
    for joint in joints.values():
        children.setdefault(joint.parent, []).append(joint.child)
    seen, stack = {roots[0]}, [roots[0]]
    while stack:
        for child in children.get(stack.pop(), []):
            if child not in seen:
                seen.add(child)
                stack.append(child)
    cut_off = [name for name in links if name not in seen]
    if cut_off:
        sink.error(span, "E0413", f"robot '{robot}': links {', '.join(cut_off)} form a cycle "
                   f"that is not connected to the root link '{roots[0]}'")
        return None
    return roots[0]
