"""Name editing rules: prefixes, suffixes and regular-expression replacements.

A rule applies to one kind of name (or to all). For a name of kind K, the rules for
all kinds apply first, then those for K; within a rule, the replacements apply in
order, then the prefix and the suffix — neither is added twice (Phobos's meaning).
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Literal

from mpc.core.record import record

Scope = Literal["all", "link", "joint", "collision", "visual", "submechanism"]
SCOPES: tuple[Scope, ...] = ("all", "link", "joint", "collision", "visual", "submechanism")


@record(slots=True, kw_only=True)
class NameRule:
    """One scope's editing: replacements (pattern, replacement) in order, then prefix, suffix."""

    scope: Scope = "all"
    prefix: str = ""
    suffix: str = ""
    replacements: tuple[tuple[str, str], ...] = ()


@lru_cache(maxsize=1024)
def _compiled(pattern: str) -> re.Pattern[str]:
    return re.compile(pattern)


def edit_name(name: str, kind: str, rules: tuple[NameRule, ...]) -> str:
    """`name` (of `kind`) after the rules that concern it."""
    for scope in ("all", kind):
        for rule in rules:
            if rule.scope != scope:
                continue
            for pattern, replacement in rule.replacements:
                name = _compiled(pattern).sub(replacement, name)
            if rule.prefix and not name.startswith(rule.prefix):
                name = rule.prefix + name
            if rule.suffix and not name.endswith(rule.suffix):
                name = name + rule.suffix
    return name


LINK_SUFFIX = "_Link"


def without_link_suffix(link: str) -> str:
    """`joint_equals_link_name`: a joint's name from its child link's, minus a `_link` ending
    (in any case), as Phobos names it."""
    return link[:-5] if link.upper().endswith("_LINK") else link


def takes_link_suffix(link: str, mode: str, parent_joint: str | None) -> bool:
    """Whether `append_link_suffix: mode` appends `_Link` to `link` (its name after the other
    editing; `parent_joint`: the name of the joint above it, after editing). Never to a name
    that ends in `link` (any case); ALWAYS to every other; NAME_DUPLICATES to one named as the
    joint above it."""
    if not mode or link.upper().endswith("LINK"):
        return False
    return mode == "ALWAYS" or link == parent_joint


def bad_pattern(pattern: str) -> str | None:
    """Why `pattern` is not a regular expression, or None."""
    try:
        re.compile(pattern)
    except re.error as e:
        return str(e)
    return None
