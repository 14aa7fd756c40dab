"""The annotations of two models → their changes: motors, sensors, poses, submechanisms, cut
joints, the robot's annotation categories and each link's and joint's annotations.

Each is compared as plain data (dataclasses and mappings as dicts, sequences as lists), with
the old model's link and joint names renamed to the new ones first, so a renamed link does
not change every sensor on it. Numbers are equal within `default` (a pose's joint values
within `rad`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping
from typing import Any

from mpc.checks.diff_change import Change
from mpc.checks.diff_match import Matching
from mpc.ir.program import Tolerances
from mpc.ir.robot import Robot

_SKIPPED = frozenset({"span", "comments", "inner_comments"})


def plain(value: Any, names: Mapping[str, str] | None = None) -> Any:
    """`value` as JSON-like data; strings that are keys of `names` become their values."""
    names = names or {}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: plain(getattr(value, f.name), names) for f in dataclasses.fields(value)
                if f.name not in _SKIPPED}
    if isinstance(value, Mapping):
        return {str(names.get(str(k), k)): plain(v, names) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v, names) for v in value]
    if isinstance(value, str):
        return names.get(value, value)
    if isinstance(value, bool | int | float) or value is None:
        return value
    return str(value)


def differences(a: Any, b: Any, eps: float, at: str = "") -> list[str]:
    """Where plain data `a` and `b` differ: `key: old → new` each (numbers within eps)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(a.keys() | b.keys()):
            out += differences(a.get(k), b.get(k), eps, f"{at}.{k}" if at else k)
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b, strict=True))
                for d in differences(x, y, eps, f"{at}[{i}]")]
    if isinstance(a, int | float) and isinstance(b, int | float) and not isinstance(a, bool) \
            and not isinstance(b, bool):
        return [] if math.isclose(a, b, abs_tol=eps) else [f"{at or 'value'}: {a:g} → {b:g}"]
    return [] if a == b else [f"{at or 'value'}: {_short(a)} → {_short(b)}"]


def _short(v: Any) -> str:
    text = "none" if v is None else str(v)
    return text if len(text) <= 60 else text[:57] + "…"


def _where(value: Any) -> str:
    """` (IMU on link 'base')`: a sensor's or motor's type and place, when it has them."""
    if not isinstance(value, dict):
        return ""
    kind = value.get("type") if isinstance(value.get("type"), str) else ""
    place = next((f"{key} '{value[key]}'" for key in ("link", "joint")
                  if isinstance(value.get(key), str)), "")
    said = " on ".join(p for p in (kind, place) if p)
    return f" ({said})" if said else ""


def _keyed(element: str, old: Mapping[str, Any], new: Mapping[str, Any], names: Mapping[str, str],
           eps: float) -> Iterator[Change]:
    """Changes of elements keyed by name (motors, sensors, poses, cut joints)."""
    a = {str(names.get(k, k)): plain(v, names) for k, v in old.items()}
    b = {str(k): plain(v) for k, v in new.items()}
    for name in sorted(a.keys() | b.keys()):
        if name not in a:
            yield Change(element, name, "added", None, b[name], f"{element} '{name}' added{_where(b[name])}")
        elif name not in b:
            yield Change(element, name, "removed", a[name], None,
                         f"{element} '{name}' removed{_where(a[name])}")
        else:
            said = differences(a[name], b[name], eps)
            if said:
                yield Change(element, name, "changed", a[name], b[name],
                             f"{element} '{name}': " + "; ".join(said))


def extras(old: Robot, new: Robot, matching: Matching, tol: Tolerances) -> Iterator[Change]:
    """The changes of the annotations (see the module's docstring)."""
    names = matching.renamed()
    yield from _keyed("motor", old.motors, new.motors, names, tol.default)
    yield from _keyed("sensor", old.sensors, new.sensors, names, tol.default)
    yield from _keyed("pose", old.poses, new.poses, names, tol.rad)
    yield from _keyed("cut joint", old.cut_joints, new.cut_joints, names, tol.default)
    yield from _keyed("submechanism", {s.name: s for s in old.submechanisms},
                      {s.name: s for s in new.submechanisms}, names, tol.default)
    yield from _keyed("annotation", old.annotations, new.annotations, names, tol.default)
    for element, pairs, a_all, b_all in (("link", matching.links, old.links, new.links),
                                         ("joint", matching.joints, old.joints, new.joints)):
        for a, b in sorted(pairs.items(), key=lambda p: p[1]):
            said = differences(plain(a_all[a].annotations, names), plain(b_all[b].annotations),
                               tol.default)
            if said:
                yield Change(element, b, "annotations", plain(a_all[a].annotations, names),
                             plain(b_all[b].annotations), f"{element} '{b}' annotations: " + "; ".join(said))
