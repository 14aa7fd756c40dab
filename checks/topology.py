"""Tests of the kinematic tree: topological_self_consistency and compare_amount_joints."""

from __future__ import annotations

from mpc.checks.protocol import Result, failed, first_of, passed, verdict
from mpc.checks.registry import Context, register
from mpc.ir.program import ModelTest
from mpc.ir.robot import Robot

MOVABLE = frozenset({"revolute", "continuous", "prismatic", "floating", "planar"})


def tree_problems(robot: Robot) -> list[str]:
    """Why the links and joints are not one tree: unknown links, a link with two parents,
    more than one root, a cycle, |links| ≠ |joints| + 1."""
    problems = []
    parents: dict[str, str] = {}
    for j in sorted(robot.joints.values(), key=lambda j: j.name):
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in robot.links:
                problems.append(f"joint '{j.name}' names {role} link '{link}', which does not exist")
        if j.child in parents:
            problems.append(f"link '{j.child}' has two parent joints: '{parents[j.child]}' and '{j.name}'")
        parents[j.child] = j.name
    roots = sorted(set(robot.links) - set(parents))
    if len(roots) != 1:
        problems.append(f"{len(roots)} root links ({', '.join(roots) or 'none'}); a tree has one")
    for link in sorted(parents):
        seen, at = {link}, link
        while at in parents:
            at = robot.joints[parents[at]].parent
            if at in seen:
                problems.append(f"link '{link}' is in a cycle of joints")
                break
            seen.add(at)
    if len(robot.links) != len(robot.joints) + 1:
        problems.append(f"{len(robot.links)} links and {len(robot.joints)} joints; a tree has one "
                        "link more than joints")
    return problems


@register("topological_self_consistency")
def topological_self_consistency(ctx: Context, test: ModelTest) -> Result:
    """The model is a tree; against the compare model no link or joint was removed or
    renamed and no joint changed its type. Additions are reported, not failed."""
    name = test.name
    new = ctx.built.robot
    problems = tree_problems(new)
    details: list[str] = []
    if ctx.old is not None:
        old = ctx.old.robot
        for kind, a, b in (("link", old.links, new.links), ("joint", old.joints, new.joints)):
            for gone in sorted(set(a) - set(b)):
                problems.append(f"{kind} '{gone}' was removed or renamed")
            for added in sorted(set(b) - set(a)):
                details.append(f"added {kind} '{added}'")
        for j in sorted(set(old.joints) & set(new.joints)):
            if old.joints[j].type != new.joints[j].type:
                problems.append(f"joint '{j}' changed its type from {old.joints[j].type} to "
                                f"{new.joints[j].type}")
    elif ctx.plan.compare is not None:
        problems.append(f"the compare model cannot be loaded: {ctx.old_problem}")
    what = "a tree" + (" with no breaking change against the compare model" if ctx.old else
                       " (no compare model: only the tree was checked)" if ctx.plan.compare is None else "")
    if problems:
        return failed(name, first_of(problems), figure=float(len(problems)), unit="problems",
                      details=(*problems, *details))
    return passed(name, what, figure=0.0, unit="problems", details=tuple(details))


@register("compare_amount_joints", needs="both")
def compare_amount_joints(ctx: Context, test: ModelTest) -> Result:
    """The same number of movable joints as the compare model."""
    count_new = sum(j.type in MOVABLE for j in ctx.built.robot.joints.values())
    count_old = sum(j.type in MOVABLE for j in ctx.compare.robot.joints.values())
    return verdict(test.name, count_new == count_old,
                   f"{count_new} movable joints, the compare model has {count_old} (compared exactly)",
                   figure=float(count_new - count_old), unit="joints")
