"""Frame (link) ops: new frames, moving frames and links, re-rooting, annotations.

Their `apply` is written by the model-editing work; until then `SUPPORTED` is False
and compiling a definition that uses them is a "not supported yet" error, while
`mpc check` already checks every name they use.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from mpc.ir.names import Names
from mpc.ir.ops import Effects, Op, Ref

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


@dataclass(frozen=True, kw_only=True)
class AddFrame(Op):
    """Add link `link` below `parent` through a new joint `joint` of `type` at (xyz, rpy).

    mass: when given, the link gets a point mass (inertia diag(1e-6)).
    """

    WHAT = "new frame"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    link: str
    parent: str
    joint: str
    type: str = "fixed"
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 | None = None
    mass: float | None = None
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.parent, "parent"),)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.link in names.links:
            effects.error("E0311", f"frame '{self.link}' exists already; a new frame needs a new "
                          "name (to edit the link, leave out its joint/parent)", "link")
            return names
        if self.joint in names.joints:
            effects.error("E0311", f"the joint '{self.joint}' of new frame '{self.link}' exists "
                          "already", "joint")
            return names
        return replace(names, links=names.links | {self.link},
                       joints={**names.joints, self.joint: (self.parent, self.link)})


@dataclass(frozen=True, kw_only=True)
class MakeRoot(Op):
    """Make `link` the root: the joints on the path to it are turned around."""

    WHAT = "make_root"

    SUPPORTED = False
    link: str

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.link, "link"),)

    def effect(self, names: Names, effects: Effects) -> Names:
        by_child = {c: (j, p) for j, (p, c) in names.joints.items()}
        joints = dict(names.joints)
        link = self.link
        while link in by_child:
            joint, parent = by_child[link]
            joints[joint] = (link, parent)
            link = parent
        return replace(names, joints=joints, root=self.link)


@dataclass(frozen=True, kw_only=True)
class TransformLink(Op):
    """Move `link` with its visuals, collisions and inertial by X (xyz, rpy) in its own frame."""

    WHAT = "transform"

    SUPPORTED = False
    link: str
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.link, "link"),)


@dataclass(frozen=True, kw_only=True)
class TransformFrame(TransformLink):
    """Move only the frame of `link`: its children, visuals, collisions and inertial stay put."""


@dataclass(frozen=True, kw_only=True)
class ReparentLink(Op):
    """Hang `link` below `parent`, keeping its pose in the root frame (at q = 0)."""

    WHAT = "reparent_to"

    SUPPORTED = False
    link: str
    parent: str

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.link, "link"), Ref("link", self.parent, "parent"))

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.parent in names.subtree(self.link):
            effects.error("E0312", f"cannot reparent '{self.link}' to '{self.parent}', which is "
                          f"below it: the tree would become a cycle", "parent")
            return names
        if self.link == names.root:
            effects.error("E0312", f"cannot reparent the root link '{self.link}'", "link")
            return names
        return replace(names, joints={j: ((self.parent, c) if c == self.link else (p, c))
                                      for j, (p, c) in names.joints.items()})


@dataclass(frozen=True, kw_only=True)
class EstimateMissingComs(Op):
    """Set the COM of each of `links` (all when empty) whose COM is at its origin, from its
    collision geometry."""

    WHAT = "estimate_missing_coms"

    SUPPORTED = False
    links: tuple[str, ...] = ()

    def reads(self) -> tuple[Ref, ...]:
        return tuple(Ref("link", n, "links") for n in self.links)


@dataclass(frozen=True, kw_only=True)
class AnnotateLinks(Op):
    """Free annotations (for SMURF) on `links` (all when empty); material: set the visuals'."""

    WHAT = "frames"

    SUPPORTED = False
    links: tuple[str, ...] = ()
    material: str | None = None
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        refs = [Ref("link", n, "links") for n in self.links]
        if self.material:
            refs.append(Ref("material", self.material, "material"))
        return tuple(refs)
