"""The part of a robot that a `submodel` export writes: from `start` down to the `stop` links,
then without the joints it merges away (remove_joints, remove_fixed, abstract_model)."""

from __future__ import annotations

import re
from dataclasses import replace

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.ir.names import Names
from mpc.ir.ops import CompleteSubmechanisms, Effects
from mpc.ir.ops.assembly import keep_links
from mpc.ir.program import SubmodelExport
from mpc.ir.robot import Robot


def matching(pattern: str, links: set[str]) -> set[str]:
    """The links a `stop` entry names: the link of that name, or those its regex matches."""
    if pattern in links:
        return {pattern}
    try:
        matcher = re.compile(pattern)
    except re.error:
        return set()
    return {link for link in links if matcher.fullmatch(link)}


def part_links(names: Names, export: SubmodelExport, sink: Sink) -> tuple[str, set[str]] | None:
    """The submodel's root and links, from the robot's names (`mpc check` has no more);
    None (with an error) when start or a stop names no link."""
    start = export.start or names.root
    if start not in names.links:
        sink.error(export.span, "E0310", f"submodel '{export.name}' starts at unknown link '{start}'"
                   f"{did_you_mean(start, set(names.links))}")
        return None
    below = names.subtree(start)
    kept = set(below)
    if export.stop:
        stops: set[str] = set()
        for pattern in export.stop:
            found = matching(pattern, below)
            if not found:
                sink.error(export.span, "E0310", f"submodel '{export.name}': stop '{pattern}' names no "
                           f"link below '{start}'{did_you_mean(pattern, below)}")
                return None
            stops |= found
        for stop in stops:
            kept -= names.subtree(stop) - {stop}
        if not export.include_unstopped_branches:  # the links from each stop up to start
            parents = {child: parent for parent, child in names.joints.values()}
            kept = {start}
            for link in stops:
                while link in parents:
                    if link in below:
                        kept.add(link)
                    link = parents[link]
    return start, kept


def cut(robot: Robot, export: SubmodelExport, sink: Sink) -> Robot | None:
    """The submodel, named after it; None (with an error) when start or a stop names no link."""
    found = part_links(Names.of(robot), export, sink)
    if found is None:
        return None
    start, kept = found
    part = replace(keep_links(robot, kept, start), name=export.name)
    if export.no_submechanisms:
        part = replace(part, submechanisms=())
    merged = _merged(part, export, sink)
    if merged is not None:
        merged = _moved_axes(merged, export, sink)
    if merged is not None and export.name_replacements:
        merged = _renamed(merged, export, sink)
    return merged


def _moved_axes(part: Robot, export: SubmodelExport, sink: Sink) -> Robot | None:
    """move_joint_axis_to_intersection, joint by joint (ir/ops/joints.py)."""
    from mpc.ir.ops.joints import MoveJointAxisToIntersection

    for joint, (a, b) in export.move_joint_axis_to_intersection.items():
        for name in (joint, a, b):
            if name not in part.joints:
                sink.error(export.span, "E0310", f"submodel '{export.name}': move_joint_axis_to_intersection "
                           f"names '{name}', which is not a joint of the submodel"
                           f"{did_you_mean(name, set(part.joints))}")
                return None
        op = MoveJointAxisToIntersection(span=export.span, joint=joint, a=a, b=b)
        before = len(sink.diagnostics)
        part = op.apply(part, Effects(sink, op))
        if sink.has_errors() and len(sink.diagnostics) > before:
            return None
    return part


def _renamed(part: Robot, export: SubmodelExport, sink: Sink) -> Robot | None:
    """name_replacements on every name (name editing's rules, ir/naming.py); E0302 when two
    links or two joints would get one name."""
    from mpc.ir.naming import NameRule
    from mpc.ir.ops import EditNames

    op = EditNames(span=export.span, rules=(NameRule(replacements=export.name_replacements),))
    before = len(sink.diagnostics)
    op.effect(Names.of(part), Effects(sink, op))
    if len(sink.diagnostics) > before:
        return None
    return replace(op.apply(part, Effects(sink, op)), name=export.name)


def _merged(part: Robot, export: SubmodelExport, sink: Sink) -> Robot | None:
    """The submodel after remove_joints, remove_fixed and abstract_model (ir/merge.py)."""
    from mpc.ir.merge import merge_joints

    gone: set[str] = set()
    for pattern in export.remove_joints:
        found = matching(pattern, set(part.joints))
        if not found:
            sink.error(export.span, "E0310", f"submodel '{export.name}': remove_joints '{pattern}' names "
                       f"no joint of the submodel{did_you_mean(pattern, set(part.joints))}")
            return None
        gone |= found
    if export.remove_fixed:
        gone |= {n for n, j in part.joints.items() if j.type == "fixed"}
    if export.abstract_model:
        if not part.submechanisms:
            sink.warning(export.span, "W0522", f"submodel '{export.name}': abstract_model needs "
                         "submechanisms; the submodel has none, so it keeps its joints (as Phobos does)")
        else:
            gone |= set(part.joints) - abstract_joints(part)
    merged = merge_joints(part, gone, sink, export.span)
    if merged is not None and export.abstract_model and part.submechanisms:
        # The abstract model's tree is serial: its submechanisms are made anew, as Phobos does.
        op = CompleteSubmechanisms(span=export.span)
        merged = op.apply(replace(merged, submechanisms=()), Effects(sink, op))
    return merged


def abstract_joints(robot: Robot) -> set[str]:
    """The joints of the abstract model (Phobos's meaning): the fixed ones, the
    submechanisms' independent joints and the exoskeletons' dependent ones."""
    kept = {n for n, j in robot.joints.items() if j.type == "fixed"}
    for sm in robot.submechanisms:
        key = "jointnames_dependent" if sm.exoskeleton else "jointnames_independent"
        kept |= {str(j) for j in sm.definition.get(key, ())}
    return kept & set(robot.joints)
