"""Name editing rules: prefixes, suffixes and regular-expression replacements.

A rule applies to one kind of name (or to all). For a name of kind K, the rules for
all kinds apply first, then those for K; within a rule, the replacements apply in
order, then the prefix and the suffix — neither is added twice (Phobos's meaning).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

Scope = Literal["all", "link", "joint", "collision", "visual", "submechanism"]
SCOPES: tuple[Scope, ...] = ("all", "link", "joint", "collision", "visual", "submechanism")


@dataclass(frozen=True, slots=True, kw_only=True)
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


def bad_pattern(pattern: str) -> str | None:
    """Why `pattern` is not a regular expression, or None."""
    try:
        re.compile(pattern)
    except re.error as e:
        return str(e)
    return None
