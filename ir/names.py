"""Names: the symbolic view of a robot that name checks need — no geometry, no numbers.

`mpc check` runs every op on Names instead of on a Robot, so a whole definition is
checked against the names of its input models without reading a mesh. Names keeps
the tree (each joint's parent and child) because cuts and attachments need it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import field, replace
from typing import Literal

from mpc.core.record import record
from mpc.ir.robot import Robot

Kind = Literal["link", "joint", "collision", "visual", "material", "motor", "sensor", "pose",
               "submechanism"]


@record(slots=True)
class Names:
    """The names of a robot.

    joints: joint name → (parent link, child link). root: the root link.
    collisions, visuals: names of named collisions and visuals, by link.
    """

    links: frozenset[str]
    joints: Mapping[str, tuple[str, str]]
    root: str
    collisions: Mapping[str, frozenset[str]] = field(default_factory=dict)
    visuals: Mapping[str, frozenset[str]] = field(default_factory=dict)
    materials: frozenset[str] = frozenset()
    others: Mapping[str, frozenset[str]] = field(default_factory=dict)
    gone: Mapping[str, str] = field(default_factory=dict)  # removed name → what removed it

    @classmethod
    def of(cls, robot: Robot) -> Names:
        return cls(
            links=frozenset(robot.links),
            joints={j.name: (j.parent, j.child) for j in robot.joints.values()},
            root=robot.root,
            collisions={n: frozenset(c.name for c in link.collisions if c.name)
                        for n, link in robot.links.items()},
            visuals={n: frozenset(v.name for v in link.visuals if v.name)
                     for n, link in robot.links.items()},
            materials=frozenset(robot.materials),
            others={"pose": frozenset(robot.poses)} if robot.poses else {},
        )

    def all(self, kind: Kind) -> frozenset[str]:
        """Every name of one kind."""
        if kind == "link":
            return self.links
        if kind == "joint":
            return frozenset(self.joints)
        if kind == "collision":
            return frozenset().union(*self.collisions.values()) if self.collisions else frozenset()
        if kind == "visual":
            return frozenset().union(*self.visuals.values()) if self.visuals else frozenset()
        if kind == "material":
            return self.materials
        return self.others.get(kind, frozenset())

    def children(self) -> dict[str, list[str]]:
        out: dict[str, list[str]] = {}
        for parent, child in self.joints.values():
            out.setdefault(parent, []).append(child)
        return out

    def subtree(self, link: str) -> set[str]:
        """`link` and every link below it."""
        children = self.children()
        seen, stack = {link}, [link]
        while stack:
            for c in children.get(stack.pop(), []):
                if c not in seen:
                    seen.add(c)
                    stack.append(c)
        return seen

    def keep(self, links: Iterable[str], root: str | None = None, why: str = "") -> Names:
        """Only `links` and the joints between them (a cut of the tree); `why` says what cut."""
        kept = frozenset(links)
        joints = {j for j, (p, c) in self.joints.items() if p in kept and c in kept}
        gone = dict(self.gone)
        gone.update((n, why) for n in (self.links - kept) | (set(self.joints) - joints))
        return replace(
            self, links=kept, root=root or self.root, gone=gone,
            joints={j: pc for j, pc in self.joints.items() if pc[0] in kept and pc[1] in kept},
            collisions={k: v for k, v in self.collisions.items() if k in kept},
            visuals={k: v for k, v in self.visuals.items() if k in kept},
        )

    def with_other(self, kind: Kind, names: Iterable[str]) -> Names:
        others = dict(self.others)
        others[kind] = others.get(kind, frozenset()) | frozenset(names)
        return replace(self, others=others)
