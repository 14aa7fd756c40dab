"""Two robot values → the semantic changes between them (`mpc diff`, the merge request's diff).

Links and joints are paired by name, or as renamed by topology and pose (checks/diff_match.py);
each pair is compared property by property, then the shapes (checks/diff_shapes.py), the
annotations (checks/diff_extras.py) and the whole robot at the zero pose. A change is reported
when it exceeds the model tests' tolerances (ir/program.py Tolerances, as `mpc test` uses them):
masses by `mass`, lengths and positions by `distance`, angles by `rad`, and everything else
(effort, velocity, damping, friction, annotations' numbers) by `default`; a principal moment
of inertia by `default` relative to the link's largest.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import field
from typing import Any

import numpy as np

from mpc.checks.diff_change import Change
from mpc.checks.diff_extras import extras
from mpc.checks.diff_match import Matching, match
from mpc.checks.diff_shapes import link_shapes
from mpc.checks.pictures import turned
from mpc.core.record import record
from mpc.ir.inertia import body, combine, placed
from mpc.ir.kinematics import links_in_root
from mpc.ir.program import Tolerances
from mpc.ir.robot import Inertial, Joint, Link, Robot


@record(frozen=False)
class Diff:
    """The changes from `old` to `new`, in report order, and how their links and joints pair."""

    changes: list[Change] = field(default_factory=list)
    matching: Matching = field(default_factory=Matching)

    @property
    def changed(self) -> bool:
        return bool(self.changes)


def _num(x: float | None) -> str:
    return "none" if x is None else f"{x:.6g}"


def _differs(a: float | None, b: float | None, eps: float) -> bool:
    return (a is None) != (b is None) or (a is not None and b is not None and abs(a - b) > eps)


def _vec(v: Any) -> list[float] | None:
    return None if v is None else [round(float(x), 9) for x in v]


def _inertia_changes(name: str, a: Inertial | None, b: Inertial | None, tol: Tolerances) -> Iterator[Change]:
    ma, mb = (i.mass if i else 0.0 for i in (a, b))
    if abs(ma - mb) > tol.mass:
        yield Change("link", name, "mass", ma, mb, f"link '{name}': mass {ma:.6g} → {mb:.6g} kg "
                     f"({mb - ma:+.6g})")
    ba, bb = body(a), body(b)
    if a is not None and b is not None and float(np.linalg.norm(ba.com - bb.com)) > tol.distance:
        d = float(np.linalg.norm(ba.com - bb.com))
        yield Change("link", name, "com", _vec(ba.com), _vec(bb.com),
                     f"link '{name}': centre of mass moved by {d:.4g} m")
    wa, va = np.linalg.eigh(ba.I)
    wb, vb = np.linalg.eigh(bb.I)
    scale = max(float(np.max(np.abs(wa), initial=0.0)), float(np.max(np.abs(wb), initial=0.0)))
    eps = tol.default * scale
    if scale > 0 and float(np.max(np.abs(wa - wb))) > eps:
        yield Change("link", name, "inertia", _vec(wa), _vec(wb),
                     f"link '{name}': principal moments of inertia "
                     f"{', '.join(f'{x:.4g}' for x in wa)} → {', '.join(f'{x:.4g}' for x in wb)} kg·m²")
        return
    for k in range(3):  # an axis of a moment distinct from the others
        if scale > 0 and all(abs(wa[k] - wa[j]) > eps for j in range(3) if j != k):
            angle = float(np.arccos(np.clip(abs(float(va[:, k] @ vb[:, k])), 0.0, 1.0)))
            if angle > tol.rad:
                yield Change("link", name, "inertia axes", _vec(va[:, k]), _vec(vb[:, k]),
                             f"link '{name}': principal axes of inertia turned by {angle:.4g} rad")
                return


def _link_changes(a: Link, b: Link, tol: Tolerances, old: Robot, new: Robot) -> Iterator[Change]:
    if a.name != b.name:
        yield Change("link", b.name, "renamed", a.name, b.name, f"link '{a.name}' renamed to '{b.name}'")
    yield from _inertia_changes(b.name, a.inertial, b.inertial, tol)
    yield from link_shapes(a, b, tol, old.materials, new.materials)


def _limit_changes(a: Joint, b: Joint, tol: Tolerances) -> list[str]:
    la, lb = a.limit, b.limit
    position = tol.distance if b.type == "prismatic" else tol.rad
    out = []
    for key, eps in (("lower", position), ("upper", position), ("effort", tol.default),
                     ("velocity", tol.default)):
        x, y = getattr(la, key, None), getattr(lb, key, None)
        if b.type in ("fixed", "floating") or (b.type == "continuous" and key in ("lower", "upper")):
            continue
        if _differs(x, y, eps):
            out.append(f"{key} {_num(x)} → {_num(y)}")
    return out


def _joint_changes(a: Joint, b: Joint, m: Matching, tol: Tolerances) -> Iterator[Change]:
    n = b.name
    if a.name != b.name:
        yield Change("joint", n, "renamed", a.name, b.name, f"joint '{a.name}' renamed to '{b.name}'")
    if m.links.get(a.parent) != b.parent:
        yield Change("joint", n, "parent", a.parent, b.parent,
                     f"joint '{n}': parent link {a.parent} → {b.parent}")
    if a.type != b.type:
        yield Change("joint", n, "type", a.type, b.type, f"joint '{n}': type {a.type} → {b.type}")
    d, angle = turned(a.origin, b.origin)
    if d > tol.distance or angle > tol.rad:
        yield Change("joint", n, "origin", _origin(a), _origin(b),
                     f"joint '{n}': origin moved by {d:.4g} m, turned by {angle:.4g} rad")
    axes = [np.asarray(j.axis or (1.0, 0.0, 0.0), dtype=float) for j in (a, b)]
    axes = [x / (np.linalg.norm(x) or 1.0) for x in axes]
    turn = float(np.arccos(np.clip(float(axes[0] @ axes[1]), -1.0, 1.0)))
    if b.type not in ("fixed", "floating") and a.type == b.type and turn > tol.rad:
        yield Change("joint", n, "axis", _vec(axes[0]), _vec(axes[1]),
                     f"joint '{n}': axis {_fmt(axes[0])} → {_fmt(axes[1])}")
    limits = _limit_changes(a, b, tol)
    if limits:
        yield Change("joint", n, "limit", _limit(a), _limit(b), f"joint '{n}': limit " + ", ".join(limits))
    da, db = ({k: getattr(j.dynamics, k, None) for k in ("damping", "friction")} for j in (a, b))
    dyn = [f"{k} {_num(da[k])} → {_num(db[k])}" for k in da
           if abs((da[k] or 0.0) - (db[k] or 0.0)) > tol.default]
    if dyn:
        yield Change("joint", n, "dynamics", da, db, f"joint '{n}': dynamics " + ", ".join(dyn))
    mimic = [_mimic(a.mimic, m), _mimic(b.mimic, None)]
    if mimic[0] != mimic[1] and (mimic[0] is None or mimic[1] is None or mimic[0][0] != mimic[1][0] or any(
            abs(x - y) > tol.default for x, y in zip(mimic[0][1:], mimic[1][1:], strict=True))):
        yield Change("joint", n, "mimic", mimic[0], mimic[1], f"joint '{n}': mimic {_said(mimic[0])} → "
                     f"{_said(mimic[1])}")


def _mimic(mimic: Any, m: Matching | None) -> tuple[str, float, float] | None:
    if mimic is None:
        return None
    joint = m.joints.get(mimic.joint, mimic.joint) if m is not None else mimic.joint
    return (str(joint), 1.0 if mimic.multiplier is None else mimic.multiplier, mimic.offset or 0.0)


def _said(mimic: tuple[str, float, float] | None) -> str:
    return "none" if mimic is None else f"{mimic[0]} ×{mimic[1]:g} {mimic[2]:+g}"


def _fmt(v: np.ndarray) -> str:
    return "(" + " ".join(f"{x:.4g}" for x in v) + ")"


def _origin(j: Joint) -> dict[str, list[float] | None]:
    o = j.origin
    return {"xyz": _vec(o.xyz) if o else [0.0] * 3, "rpy": _vec(o.rpy) if o else [0.0] * 3}


def _limit(j: Joint) -> dict[str, float | None]:
    return {k: getattr(j.limit, k, None) for k in ("lower", "upper", "effort", "velocity")}


def _whole(robot: Robot) -> tuple[float, np.ndarray, float]:
    """Total mass, its centre in the root and the reach (the farthest link origin from the
    root's) at the zero pose."""
    X = links_in_root(robot)
    total = combine(*(placed(body(link.inertial), X[name]) for name, link in robot.links.items()),
                    body(None))
    reach = max((float(np.linalg.norm(x[:3, 3])) for x in X.values()), default=0.0)
    return total.mass, total.com, reach


def _robot_changes(old: Robot, new: Robot, tol: Tolerances) -> Iterator[Change]:
    (ma, ca, ra), (mb, cb, rb) = _whole(old), _whole(new)
    if abs(ma - mb) > tol.mass:
        yield Change("robot", new.name, "total mass", ma, mb,
                     f"total mass {ma:.6g} → {mb:.6g} kg ({mb - ma:+.6g})")
    if float(np.linalg.norm(ca - cb)) > tol.distance:
        yield Change("robot", new.name, "com", _vec(ca), _vec(cb), f"centre of mass moved by "
                     f"{float(np.linalg.norm(ca - cb)):.4g} m at the zero pose")
    if abs(ra - rb) > tol.distance:
        yield Change("robot", new.name, "reach", ra, rb, f"reach at the zero pose {ra:.4g} → {rb:.4g} m")


def diff(old: Robot, new: Robot, tol: Tolerances | None = None) -> Diff:
    """The changes from `old` to `new` beyond `tol` (default: the model tests' tolerances)."""
    tol = tol or Tolerances()
    m = match(old, new, tol)
    out = Diff(matching=m)
    gone_links = sorted(set(old.links) - set(m.links))
    new_links = sorted(set(new.links) - set(m.links.values()))
    gone_joints = sorted(set(old.joints) - set(m.joints))
    new_joints = sorted(set(new.joints) - set(m.joints.values()))
    out.changes += [Change("link", n, "removed", n, None, f"link '{n}' removed") for n in gone_links]
    out.changes += [Change("link", n, "added", None, n, f"link '{n}' added") for n in new_links]
    out.changes += [Change("joint", n, "removed", n, None, f"joint '{n}' removed") for n in gone_joints]
    out.changes += [Change("joint", n, "added", None, n,
                           f"joint '{n}' added ({new.joints[n].type}, {new.joints[n].parent} → "
                           f"{new.joints[n].child})") for n in new_joints]
    for a, b in sorted(m.links.items(), key=lambda p: p[1]):
        out.changes += _link_changes(old.links[a], new.links[b], tol, old, new)
    for a, b in sorted(m.joints.items(), key=lambda p: p[1]):
        out.changes += _joint_changes(old.joints[a], new.joints[b], m, tol)
    out.changes += extras(old, new, m, tol)
    out.changes += _robot_changes(old, new, tol)
    return out


def changed_links(d: Diff, old: Robot, new: Robot) -> dict[str, str]:
    """{link: why} of the links the pictures colour, by their names in either model: each link
    that changed itself or whose joint changed, added, removed or renamed."""
    out: dict[str, str] = {}
    old_name = {b: a for a, b in d.matching.links.items()}
    for c in d.changes:
        link = c.name if c.element in ("link", "collision", "visual") else None
        if c.element == "joint":
            joints = old.joints if c.aspect == "removed" else new.joints
            link = joints[c.name].child if c.name in joints else None
        if link is not None:
            out.setdefault(link, c.text)
            if link in old_name and old_name[link] != link:
                out.setdefault(old_name[link], c.text)
    return out
