"""What is under the cursor: a key, a name (and of what kind), or a value; and the link or
joint a name stands for in the input models or the built robot.

What this does not do: format answers (hover.py, navigation.py).
"""

from __future__ import annotations

import re
from pathlib import Path

from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.robot import Joint, Link, Robot
from mpc.lsp.analysis import Analysis
from mpc.lsp.completion import KEYED_BY, VALUE_NAMES
from mpc.lsp.text import Lines, contains, context
from mpc.lsp.xacro_sources import find_element

_WORD = re.compile(r"[^\s:\[\],{}\"'#]+")


@record
class Target:
    """The word at the cursor. keys: the keys above it; key: its line's key; on_key: the word is
    that key; kinds: what it names (empty: no name); span: where it is (1-based, this buffer)."""

    word: str
    keys: tuple[str, ...]
    key: str | None
    on_key: bool
    kinds: tuple[str, ...]
    span: Span


def target(analysis: Analysis, line: int, col: int) -> Target | None:
    """The word at 0-based `line`, 1-based `col`, or None on blank space."""
    lines = Lines(analysis.text)
    text = lines.line(line)
    for match in _WORD.finditer(text):
        if match.start() + 1 <= col <= match.end() + 1:  # on the word or just after it
            break
    else:
        return None
    word = match.group()
    span = Span(str(analysis.path), line + 1, match.start() + 1, line + 1, match.end() + 1)
    ctx = context(lines, line, match.start() + 1)
    own = context(lines, line, len(text) + 1)
    on_key = own.key is not None and text[match.end():].lstrip().startswith(":") and ctx.key is None
    keys, key = (ctx.keys, None) if on_key else (own.keys, own.key)
    kinds: tuple[str, ...] = ()
    for site in analysis.sites:
        if contains(site.span, line + 1, match.start() + 1) and site.span.line == line + 1:
            kinds = site.kinds
            break
    else:
        if on_key and len(keys) == 2 and keys[0] == "model" and keys[1] in KEYED_BY:
            kinds = (KEYED_BY[keys[1]],)
        elif on_key and keys[:2] == ("model", "poses") and len(keys) == 3:
            kinds = ("joint",)
        elif not on_key and key in VALUE_NAMES:
            kinds = (VALUE_NAMES[key],)
    return Target(word, keys, key if not on_key else word, on_key, kinds, span)


def element(analysis: Analysis, name: str, kinds: tuple[str, ...]) -> tuple[Robot, Link | Joint] | None:
    """The link or joint `name` (the first of `kinds` that has it): in an input model as read,
    else in the robot the definition builds (after its renames)."""
    robots = list(analysis.inputs.values())
    for pool in (robots, None):
        for robot in pool if pool is not None else [analysis.built()]:
            if robot is None:
                continue
            for kind in kinds:
                if kind == "link" and name in robot.links:
                    return robot, robot.links[name]
                if kind == "joint" and name in robot.joints:
                    return robot, robot.joints[name]
    return None


_XACRO = " (expanded by xacro)"  # the file name the URDF reader gives a xacro's expansion


def written_at(analysis: Analysis, thing: Link | Joint) -> Span | None:
    """Where the link or joint is written. A xacro model's spans are lines of the URDF xacro
    expanded it to (backends/xacro_reader.py), which is no file: there, the place xacro parsed
    the element from (backends/xacro_origins.py; a renamed element too, by its line); if the
    model does not expand again, the element found in the xacro file or a file it includes
    (lsp/xacro_sources.py); else the xacro file's first line."""
    span = thing.span
    if span is None or not span.file.endswith(_XACRO):
        return span
    path = Path(span.file[:-len(_XACRO)])
    kind = "joint" if isinstance(thing, Joint) else "link"
    origin = analysis.xacro_origins(path).get(span.line)
    if origin is not None and origin[0] == kind:
        return origin[1]
    resolver = analysis.loader.options.resolver if analysis.loader is not None else PackageResolver()
    return find_element(path, kind, thing.name, resolver) or Span(str(path), 1, 1, 1, 1)
