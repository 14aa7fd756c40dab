"""Joint ops: types, limits, dynamics, mimic, motors, removal, loop closures.

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
class JointValues:
    """Values of a joint that an edit may set; None leaves a value as it is.

    lower, upper: position limits (rad or m); effort, velocity: limits.
    """

    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    friction: float | None = None
    damping: float | None = None
    spring_stiffness: float | None = None
    spring_reference: float | None = None


@dataclass(frozen=True, kw_only=True)
class Dependency:
    """q = multiplier · q_joint + offset."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True, kw_only=True)
class ReplaceJointTypes(Op):
    """Every joint of type `old` becomes type `new`, for each (old, new) pair."""

    SUPPORTED = False
    mapping: tuple[tuple[str, str], ...]


@dataclass(frozen=True, kw_only=True)
class JointDefaults(Op):
    """Fill values the joints lack, and limits that are zero (`$default`).

    joints: the joints it applies to (all when empty: `$all`).
    backup: only for movable joints without any limit (`$backup`).
    """

    WHAT = "joints $default"

    SUPPORTED = False
    values: JointValues
    joints: tuple[str, ...] = ()
    backup: bool = False

    def reads(self) -> tuple[Ref, ...]:
        return tuple(Ref("joint", n, "joints") for n in self.joints)


@dataclass(frozen=True, kw_only=True)
class EditJoint(Op):
    """Set values of `joint`: type, axis, limits and dynamics, mimic, dependencies, annotations."""

    WHAT = "joints"

    SUPPORTED = False
    joint: str
    values: JointValues = field(default_factory=JointValues)
    type: str | None = None
    axis: Vec3 | None = None
    mimic: Dependency | None = None
    depends_on: tuple[Dependency, ...] = ()
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        refs = [Ref("joint", self.joint, "joint")]
        refs += [Ref("joint", d.joint, "mimic") for d in (self.mimic, *self.depends_on) if d]
        return tuple(refs)


@dataclass(frozen=True, kw_only=True)
class SetMotor(Op):
    """Put a motor on `joint` (`active`, `motor`): name (default `<joint>_motor`) and settings."""

    WHAT = "motor"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    joint: str
    name: str
    settings: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("joint", self.joint, "joint"),)

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.with_other("motor", [self.name])


@dataclass(frozen=True, kw_only=True)
class RemoveJoint(Op):
    """Remove `joint`: its child link merges into the parent link (mass, COM and inertia
    combined, visuals and collisions moved), the child's children hang from the parent."""

    WHAT = "joint removal"

    SUPPORTED = False
    joint: str

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("joint", self.joint, "joint"),)

    def effect(self, names: Names, effects: Effects) -> Names:
        parent, child = names.joints[self.joint]
        joints = {j: ((parent if p == child else p), c)
                  for j, (p, c) in names.joints.items() if j != self.joint}
        collisions = {k: v for k, v in names.collisions.items() if k != child}
        collisions[parent] = names.collisions.get(parent, frozenset()) | names.collisions.get(
            child, frozenset())
        visuals = {k: v for k, v in names.visuals.items() if k != child}
        visuals[parent] = names.visuals.get(parent, frozenset()) | names.visuals.get(child, frozenset())
        gone = {**names.gone, child: f"the removal of joint '{self.joint}' (line {self.span.line})",
                self.joint: f"its removal (line {self.span.line})"}
        return replace(names, links=names.links - {child}, joints=joints, collisions=collisions,
                       visuals=visuals, gone=gone)


@dataclass(frozen=True, kw_only=True)
class AddCutJoint(Op):
    """A loop-closure joint `joint` between `parent` and `child`, outside the tree.

    constraint_axes: (name, axis) pairs of the constrained directions.
    """

    WHAT = "cut joint"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    joint: str
    parent: str
    child: str
    type: str = "fixed"
    constraint_axes: tuple[tuple[str | None, Vec3], ...] = ()
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.parent, "parent"), Ref("link", self.child, "child"))

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.joint in names.joints:
            effects.error("E0311", f"cut joint '{self.joint}' exists already as a joint of the tree",
                          "joint")
        return names.with_other("cut_joint", [self.joint])


@dataclass(frozen=True, kw_only=True)
class MoveJointAxisToIntersection(Op):
    """Move `joint`'s frame to where the axes of joints `a` and `b` meet."""

    WHAT = "move_joint_axis_to_intersection"

    SUPPORTED = False
    joint: str
    a: str
    b: str

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("joint", self.joint, "joint"), Ref("joint", self.a, "a"), Ref("joint", self.b, "b"))
