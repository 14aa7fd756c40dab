"""The part of a robot that a `submodel` export writes: from `start` down to the `stop` links."""

from __future__ import annotations

import re
from dataclasses import replace

from mpc.compiler.diagnostics import Sink, did_you_mean
from mpc.ir.names import Names
from mpc.ir.ops.assembly import keep_links
from mpc.ir.program import SubmodelExport
from mpc.ir.robot import Robot
from mpc.ir.tree import joints_up


def _stops(pattern: str, links: set[str]) -> set[str] | None:
    """The links a `stop` entry names: the link of that name, or those its regex matches."""
    if pattern in links:
        return {pattern}
    try:
        matcher = re.compile(pattern)
    except re.error:
        return set()
    return {link for link in links if matcher.fullmatch(link)}


def cut(robot: Robot, export: SubmodelExport, sink: Sink) -> Robot | None:
    """The submodel, named after it; None (with an error) when start or a stop names no link."""
    names = Names.of(robot)
    start = export.start or robot.root
    if start not in robot.links:
        sink.error(export.span, "E0310", f"submodel '{export.name}' starts at unknown link '{start}'"
                   f"{did_you_mean(start, set(robot.links))}")
        return None
    below = names.subtree(start)
    kept = set(below)
    if export.stop:
        stops: set[str] = set()
        for pattern in export.stop:
            found = _stops(pattern, below)
            if not found:
                sink.error(export.span, "E0310", f"submodel '{export.name}': stop '{pattern}' names no "
                           f"link below '{start}'{did_you_mean(pattern, below)}")
                return None
            stops |= found
        for stop in stops:
            kept -= names.subtree(stop) - {stop}
        if not export.include_unstopped_branches:
            kept = {start} | {j.child for stop in stops for j in joints_up(robot, stop) if j.child in below}
    return replace(keep_links(robot, kept, start), name=export.name)
