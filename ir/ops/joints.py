"""Joint ops: types, limits, dynamics, mimic, motors, removal, loop closures.

An op whose `SUPPORTED` is False is checked by `mpc check` but cannot be compiled yet.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field, replace

from mpc.core.record import record
from mpc.ir.extras import CutJoint, Motor
from mpc.ir.names import Names
from mpc.ir.ops.base import Effects, Op, Phase, Ref
from mpc.ir.refs import JointName, JointRef, LinkRef, MotorName
from mpc.ir.robot import Dynamics, Joint, Limit, Mimic, Pose, Robot

MOVABLE = ("revolute", "continuous", "prismatic", "planar", "floating")


def set_values(joint: Joint, v: JointValues, fill_only: bool = False) -> Joint:
    """`joint` with the values of `v` that are given; fill_only: only where the joint has
    none (or, for position limits, where both are zero)."""
    limit = joint.limit or Limit()
    zero_range = not limit.lower and not limit.upper

    def pick(old: float | None, new: float | None, zero_is_unset: bool = False) -> float | None:
        if new is None:
            return old
        if fill_only and old is not None and not (zero_is_unset and old == 0):
            return old
        return new

    new_limit = replace(
        limit,
        lower=pick(limit.lower, v.lower, zero_range), upper=pick(limit.upper, v.upper, zero_range),
        effort=pick(limit.effort, v.effort, True), velocity=pick(limit.velocity, v.velocity, True))
    dyn = joint.dynamics or Dynamics()
    new_dyn = replace(dyn, damping=pick(dyn.damping, v.damping), friction=pick(dyn.friction, v.friction))
    springs = {k: getattr(v, k) for k in ("spring_stiffness", "spring_reference")
               if getattr(v, k) is not None and not (fill_only and k in joint.annotations)}
    return replace(
        joint, limit=None if new_limit == Limit() and joint.limit is None else new_limit,
        dynamics=None if new_dyn == Dynamics() and joint.dynamics is None else new_dyn,
        annotations={**joint.annotations, **springs})

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


@record(kw_only=True, slots=True)
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


@record(kw_only=True)
class Dependency:
    """q = multiplier · q_joint + offset."""

    joint: JointRef
    multiplier: float = 1.0
    offset: float = 0.0


@record(kw_only=True)
class ReplaceJointTypes(Op):
    """Every joint of type `old` becomes type `new`, for each (old, new) pair."""

    PHASE = Phase.JOINTS

    mapping: tuple[tuple[str, str], ...]

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        table = dict(self.mapping)
        return replace(robot, joints={n: replace(j, type=table[j.type]) if j.type in table else j
                                      for n, j in robot.joints.items()})


@record(kw_only=True)
class JointDefaults(Op):
    """Fill values the joints lack, and limits that are zero (`$default`).

    joints: the joints it applies to (all when empty: `$all`).
    backup: only for movable joints without any limit (`$backup`).
    annotations: set where the joint has no annotation of that key.
    """

    PHASE = Phase.JOINTS

    WHAT = "joints $default"

    values: JointValues
    joints: tuple[JointRef, ...] = ()
    backup: bool = False
    annotations: Annotations = field(default_factory=dict)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        joints = dict(robot.joints)
        for name in self.joints or tuple(robot.joints):
            joint = joints[name]
            if joint.type not in MOVABLE or (self.backup and joint.limit is not None):
                continue
            joint = set_values(joint, self.values, fill_only=True)
            joints[name] = replace(joint, annotations={**self.annotations, **joint.annotations})
        return replace(robot, joints=joints)


@record(kw_only=True)
class EditJoint(Op):
    """Set values of `joint`: type, axis, limits and dynamics, mimic, dependencies, annotations."""

    PHASE = Phase.JOINTS

    WHAT = "joints"

    joint: JointRef
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

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        joint = set_values(robot.joints[self.joint], self.values)
        if self.type is not None:
            joint = replace(joint, type=self.type)
        if self.axis is not None:
            joint = replace(joint, axis=self.axis)
        if self.mimic is not None:
            joint = replace(joint, mimic=Mimic(joint=self.mimic.joint, multiplier=self.mimic.multiplier,
                                               offset=self.mimic.offset))
        annotations = dict(self.annotations)
        if self.depends_on:
            annotations["movement_depends_on"] = [
                {"joint_name": d.joint, "multiplier": d.multiplier, "offset": d.offset}
                for d in self.depends_on]
        joint = replace(joint, annotations={**joint.annotations, **annotations})
        return replace(robot, joints={**robot.joints, self.joint: joint})


# A motor's settings that are its joint's limits: (motor key, Limit field).
MOTOR_LIMITS = (("maxEffort", "effort"), ("maxSpeed", "velocity"))


@record(kw_only=True)
class SetMotor(Op):
    """Put a motor on `joint` (`active`, `motor`): name (default `<joint>_motor`) and settings."""

    PHASE = Phase.JOINTS

    WHAT = "motor"
    EFFECT_NEEDS_READS = False

    joint: JointRef
    name: MotorName
    settings: Annotations = field(default_factory=dict)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The motor; its `maxEffort` and `maxSpeed` become the joint's limit `effort` and
        `velocity` too (Phobos's readers take a motor's from its joint), with W0504 where the
        joint's said otherwise."""
        motor = Motor(name=self.name, joint=self.joint, settings=dict(self.settings))
        robot = replace(robot, motors={**robot.motors, self.name: motor})
        joint = robot.joints[self.joint]
        given = {attr: float(value) for key, attr in MOTOR_LIMITS
                 if isinstance(value := self.settings.get(key), int | float) and not isinstance(value, bool)}
        if not given or joint.type == "fixed":
            return robot
        limit = joint.limit or Limit()
        for key, attr in MOTOR_LIMITS:
            old = getattr(limit, attr)
            if attr in given and old is not None and old != given[attr]:
                effects.warning("W0504", f"the motor '{self.name}' of joint '{self.joint}' has {key} "
                                f"{given[attr]:g}, its joint's limit {attr} is {old:g}: both are now "
                                f"{given[attr]:g}, the motor's (Phobos reads a motor's from its joint)")
        limit = replace(limit, **given)
        return replace(robot, joints={**robot.joints, self.joint: replace(joint, limit=limit)})

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.with_other("motor", [self.name])


@record(kw_only=True)
class RemoveJoint(Op):
    """Remove `joint`: its child link merges into the parent link (mass, COM and inertia
    combined, visuals and collisions moved), the child's children hang from the parent."""

    PHASE = Phase.JOINTS

    WHAT = "joint removal"

    joint: JointRef

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """At q = 0: the child's inertial joins the parent's (parallel-axis theorem), its
        visuals, collisions and child joints are re-expressed in the parent (X_PV = X_PC·X_CV).
        Fragments that name the removed joint go; those that name the child link now name
        the parent."""
        from mpc.ir.inertia import body, combine, inertial
        from mpc.ir.kinematics import compose_poses
        from mpc.ir.rename import rename_fragment, xmlns_of

        removed = robot.joints[self.joint]
        for other in robot.joints.values():
            if other.mimic is not None and other.mimic.joint == self.joint:
                effects.error("E0319", f"cannot remove joint '{self.joint}': joint '{other.name}' "
                              "mimics it", "joint")
                return robot
        parent, child = robot.links[removed.parent], robot.links[removed.child]
        X_PC = removed.origin
        merged = parent.inertial
        if child.inertial is not None:
            merged = inertial(combine(body(parent.inertial), body(child.inertial, X_PC)))

        def moved(items: tuple) -> tuple:
            return tuple(replace(v, origin=compose_poses(X_PC, v.origin)) for v in items)

        links = {n: lk for n, lk in robot.links.items() if n != child.name}
        links[parent.name] = replace(
            parent, inertial=merged, visuals=parent.visuals + moved(child.visuals),
            collisions=parent.collisions + moved(child.collisions), extras=parent.extras + child.extras,
            annotations={**child.annotations, **parent.annotations})
        joints = {}
        for n, j in robot.joints.items():
            if n == self.joint:
                continue
            if j.parent == child.name:
                j = replace(j, parent=parent.name, origin=compose_poses(X_PC, j.origin))
            joints[n] = j
        to_parent = (lambda name: parent.name if name == child.name else name)  # noqa: E731
        fragments = tuple(rename_fragment(f, to_parent, lambda name: name, xmlns_of(robot))
                          for f in robot.fragments if self.joint not in f.names("joint"))
        return replace(robot, links=links, joints=joints, fragments=fragments)

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


@record(kw_only=True)
class AddCutJoint(Op):
    """A loop-closure joint `joint` between `parent` and `child`, outside the tree.

    constraint_axes: (name, axis) pairs of the constrained directions.
    """

    PHASE = Phase.JOINTS

    WHAT = "cut joint"
    EFFECT_NEEDS_READS = False

    joint: JointName
    parent: LinkRef
    child: LinkRef
    type: str = "fixed"
    constraint_axes: tuple[tuple[str | None, Vec3], ...] = ()
    annotations: Annotations = field(default_factory=dict)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.joint in names.joints:
            effects.error("E0311", f"cut joint '{self.joint}' exists already as a joint of the tree",
                          "joint")
        return names.with_other("cut_joint", [self.joint])

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The loop closure's origin is X_PC = X_RP⁻¹ · X_RC at the zero configuration."""
        from mpc.ir import transforms as tf
        from mpc.ir.kinematics import link_in_root, matrix_pose

        X_PC = tf.inverse(link_in_root(robot, self.parent)) @ link_in_root(robot, self.child)
        cut = CutJoint(name=self.joint, type=self.type, parent=self.parent, child=self.child,
                       origin=matrix_pose(X_PC), constraint_axes=self.constraint_axes,
                       annotations=dict(self.annotations), span=self.span)
        return replace(robot, cut_joints={**robot.cut_joints, self.joint: cut})


@record(kw_only=True)
class MoveJointAxisToIntersection(Op):
    """Move `joint`'s frame (its child link's frame) to where the axes of joints `a` and `b`
    meet at q = 0 — for skew axes, the middle of their closest points. Only the frame
    moves: the link's content stays where it is. This changes the kinematics on purpose
    (aligning, say, an exoskeleton's shoulder axes with the human's)."""

    PHASE = Phase.JOINTS

    joint: JointRef
    a: JointRef
    b: JointRef

    WHAT = "move_joint_axis_to_intersection"

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        import numpy as np

        from mpc.ir.kinematics import link_in_root
        from mpc.ir.ops.frames import move_frame

        lines = []
        for name in (self.a, self.b):
            j = robot.joints[name]
            X = link_in_root(robot, j.child)
            lines.append((X[:3, 3], X[:3, :3] @ np.asarray(j.axis or (1.0, 0.0, 0.0), dtype=float)))
        (p1, d1), (p2, d2) = lines
        n = np.cross(d1, d2)
        if np.linalg.norm(n) < 1e-9:
            effects.error("E0321", f"the axes of '{self.a}' and '{self.b}' are parallel: they have no "
                          "intersection to move the joint to", "a")
            return robot
        # Closest points p1 + t·d1 and p2 + s·d2 of the two lines.
        t = np.dot(np.cross(p2 - p1, d2), n) / np.dot(n, n)
        s = np.dot(np.cross(p2 - p1, d1), n) / np.dot(n, n)
        point = ((p1 + t * d1) + (p2 + s * d2)) / 2
        child = robot.joints[self.joint].child
        X_RL = link_in_root(robot, child)
        p_L = X_RL[:3, :3].T @ (point - X_RL[:3, 3])
        return move_frame(robot, child, Pose(tuple(float(x) for x in p_L)))  # type: ignore[arg-type]
