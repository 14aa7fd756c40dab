"""Hover: a key's documentation (the JSON schema's, else specs/), a link's mass, parent joint and
pose in the root frame, a joint's type, axis and limits, a number expression's value.

What this does not do: find what is under the cursor (lookup.py).
"""

from __future__ import annotations

import math

from mpc.compiler.expr import evaluate
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.robot import Joint, Link, Robot
from mpc.ir.tree import joints_up
from mpc.lsp import schema_data
from mpc.lsp.analysis import Analysis
from mpc.lsp.lookup import element, target, written_at
from mpc.lsp.structures import MARKDOWN, Hover, MarkupContent, Position
from mpc.lsp.text import Lines, contains


def hover(analysis: Analysis, position: Position) -> Hover | None:
    lines = Lines(analysis.text)
    col = lines.column(position)
    found = target(analysis, position["line"], col)
    if found is None:
        return None
    text: str | None = None
    if found.kinds:
        hit = element(analysis, found.word, found.kinds)
        if hit is not None:
            text = describe(*hit, written_at(analysis, hit[1]))
    if text is None and found.on_key:
        text = schema_data.description(found.keys, found.word)
        text = f"**{found.word}**\n\n{text}" if text else None
    if text is None and not found.on_key:
        text = _value(analysis, position["line"] + 1, col)
    if text is None:
        return None
    return Hover(contents=MarkupContent(kind=MARKDOWN, value=text), range=lines.range(found.span))


def describe(robot: Robot, thing: Link | Joint, span: Span | None) -> str:
    """Markdown about a link or a joint of `robot`, written at `span`."""
    where = f"\n\n{span.file.rsplit('/', 1)[-1]}:{span.line}" if span else ""
    if isinstance(thing, Joint):
        out = [f"**joint {thing.name}** ({thing.type}): {thing.parent} → {thing.child}"]
        if thing.axis is not None:
            out.append(f"axis: {_vec(thing.axis)}")
        limit = thing.limit
        if limit is not None:
            out.append(", ".join(f"{n}: {_g(v)}" for n, v in (("lower", limit.lower), ("upper", limit.upper),
                       ("effort", limit.effort), ("velocity", limit.velocity)) if v is not None))
        return "\n\n".join(out) + where
    out = [f"**link {thing.name}**"]
    inertial = thing.inertial
    out.append(f"mass: {_g(inertial.mass)} kg" if inertial is not None else "no inertial")
    up = joints_up(robot, thing.name)
    out.append(f"parent joint: {up[0].name} ({up[0].type})" if up else "the root link")
    # numpy (13 MiB the server would hold from its start) is loaded by the first hover on a link
    from mpc.ir.kinematics import link_in_root, matrix_pose

    pose = matrix_pose(link_in_root(robot, thing.name))
    out.append(f"pose in the root frame: xyz {_vec(pose.xyz)}, rpy {_vec(pose.rpy)}")
    return "\n\n".join(out) + where


def _value(analysis: Analysis, line: int, col: int) -> str | None:
    """The value of the number expression at the cursor (`["deg", 45]`, `pi/4`)."""
    doc = analysis.doc
    if doc is None:
        return None
    around = sorted((span for span in doc.values.values() if contains(span, line, col)),
                    key=lambda s: (s.end_line - s.line, s.end_col - s.col if s.end_line == s.line else 0))
    paths = {span: path for path, span in doc.values.items()}
    for span in around[:2]:
        data = doc.data_at(paths[span])
        if (isinstance(data, list) and len(data) == 2 and isinstance(data[0], str)) \
                or (isinstance(data, str) and not isinstance(doc.data_at(paths[span][:-1]), list)):
            value = evaluate(data, span, Sink())
            if value is not None and math.isfinite(value):
                return f"= {_g(value)}"
    return None


def _g(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".") if abs(value) < 1e6 else f"{value:g}"
    return "0" if text == "-0" else text


def _vec(values: tuple[float, ...]) -> str:
    return "[" + ", ".join(_g(v) for v in values) + "]"
