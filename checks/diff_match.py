"""Two robots → which link and which joint of the old one is which of the new one.

Names match first. A link only in the old model and one only in the new are the same link
renamed when the joints that carry them have the same name and the same (matched) parent
link, or when they hang from the same parent and lie at the same place in the root at the
zero pose (within `distance` and `rad`); a joint is renamed when it carries the same
(matched) child link. Matching runs down from the root until nothing more pairs, so a
renamed chain is found link by link; what stays unpaired was removed or added.
"""

from __future__ import annotations

from dataclasses import field

import numpy as np

from mpc.core.record import record
from mpc.ir.kinematics import links_in_root
from mpc.ir.program import Tolerances
from mpc.ir.robot import Robot
from mpc.ir.tree import parent_joint


@record(frozen=False)
class Matching:
    """links, joints: {old name: new name} of the elements in both models (renamed or not)."""

    links: dict[str, str] = field(default_factory=dict)
    joints: dict[str, str] = field(default_factory=dict)

    def renamed(self) -> dict[str, str]:
        """{old name: new name} of every renamed link or joint."""
        return {a: b for a, b in (*self.links.items(), *self.joints.items()) if a != b}


def _angle(R: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


def match(old: Robot, new: Robot, tol: Tolerances) -> Matching:
    """The matching of `old` and `new` (see the module's docstring)."""
    out = Matching(links={n: n for n in old.links if n in new.links},
                   joints={n: n for n in old.joints if n in new.joints})
    if old.root not in out.links and new.root not in set(out.links.values()):
        out.links[old.root] = new.root  # the one root of each: the same link
    X_old, X_new = links_in_root(old), links_in_root(new)
    up_old, up_new = parent_joint(old), parent_joint(new)
    while True:
        taken = set(out.links.values())
        paired = False
        for j in sorted(out.joints):  # a joint kept its name: its child is the same link
            a, b = old.joints[j], new.joints[out.joints[j]]
            if a.child not in out.links and b.child not in taken and out.links.get(a.parent) == b.parent:
                out.links[a.child] = b.child
                taken.add(b.child)
                paired = True
        candidates = []
        for a in sorted(set(old.links) - set(out.links)):
            ja = up_old.get(a)
            if ja is None or ja.parent not in out.links:
                continue
            for b in sorted(set(new.links) - taken):
                jb = up_new.get(b)
                if jb is None or jb.parent != out.links[ja.parent]:
                    continue
                d = float(np.linalg.norm(X_old[a][:3, 3] - X_new[b][:3, 3]))
                turn = _angle(X_old[a][:3, :3].T @ X_new[b][:3, :3])
                if d <= tol.distance and turn <= tol.rad:
                    candidates.append((d, turn, a, b))
        for _, _, a, b in sorted(candidates):
            if a not in out.links and b not in set(out.links.values()):
                out.links[a] = b
                paired = True
        if not paired:
            break
    new_joint_of = {j.child: j.name for j in new.joints.values()}
    for name in sorted(set(old.joints) - set(out.joints)):
        child = out.links.get(old.joints[name].child)
        b = new_joint_of.get(child) if child is not None else None
        if b is not None and b not in set(out.joints.values()):
            out.joints[name] = b
    return out
