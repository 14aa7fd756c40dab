"""Frame (link) ops: new frames, moving frames and links, re-rooting, annotations.

Geometry is done at the zero configuration, with Drake's monograms: X_PL is the pose
of link L in its parent P, T the transform the definition gives. An op whose
`SUPPORTED` is False is checked by `mpc check` but cannot be compiled yet.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import field, replace
from typing import TYPE_CHECKING

from mpc.core.record import record
from mpc.ir.names import Names
from mpc.ir.ops.base import Effects, Op, Phase
from mpc.ir.refs import JointName, LinkName, LinkRef, MaterialRef
from mpc.ir.robot import Collision, Inertia, Inertial, Joint, Link, Pose, Robot
from mpc.ir.tree import parent_joint

if TYPE_CHECKING:
    from mpc.ir.solids import Solid

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


@record(kw_only=True)
class AddFrame(Op):
    """Add link `link` below `parent` through a new joint `joint` of `type` at (xyz, rpy).

    mass: when given, the link gets a point mass (inertia diag(1e-6)).
    """

    PHASE = Phase.FRAMES

    WHAT = "new frame"
    EFFECT_NEEDS_READS = False

    link: LinkName
    parent: LinkRef
    joint: JointName
    type: str = "fixed"
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 | None = None
    mass: float | None = None
    annotations: Annotations = field(default_factory=dict)

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

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        inertial = None
        if self.mass is not None:
            small = 1e-6  # Phobos's inertia for a point mass frame
            inertial = Inertial(mass=self.mass, origin=Pose(),
                                inertia=Inertia(ixx=small, ixy=0.0, ixz=0.0, iyy=small, iyz=0.0, izz=small))
        link = Link(name=self.link, inertial=inertial, annotations=dict(self.annotations), span=self.span)
        joint = Joint(name=self.joint, type=self.type, parent=self.parent, child=self.link,  # type: ignore[arg-type]
                      origin=Pose(self.xyz, self.rpy), axis=self.axis, span=self.span)
        return replace(robot, links={**robot.links, self.link: link},
                       joints={**robot.joints, self.joint: joint})


@record(kw_only=True)
class MakeRoot(Op):
    """Make `link` the root: the joints on the path to it are turned around."""

    PHASE = Phase.FRAMES

    WHAT = "make_root"

    link: LinkRef

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """Turn the joints from the root to `link` around (at q = 0; ir/reroot.py)."""
        from mpc.ir.reroot import RerootError, reroot

        try:
            return reroot(robot, self.link)
        except RerootError as error:
            effects.error("E0551", f"cannot make '{self.link}' the root: {error}", "link")
            return robot

    def effect(self, names: Names, effects: Effects) -> Names:
        from mpc.ir.reroot import reroot_names

        return reroot_names(names, self.link)


@record(kw_only=True)
class TransformLink(Op):
    """Move `link` with its visuals, collisions and inertial by X (xyz, rpy) in its own frame."""

    PHASE = Phase.FRAMES

    WHAT = "transform"

    link: LinkRef
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.link == names.root and type(self) is TransformLink:
            effects.error("E0318", f"cannot transform the root link '{self.link}' with its content: "
                          "it has no parent to move it against (use transform_frame)", "link")
        return names

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """X_PL' = X_PL · T: the link and everything below it move."""
        from mpc.ir.kinematics import compose_poses  # numpy: not on the path of `mpc check`

        joint = parent_joint(robot).get(self.link)
        if joint is None:
            return robot
        origin = compose_poses(joint.origin, Pose(self.xyz, self.rpy))
        return replace(robot, joints={**robot.joints, joint.name: replace(joint, origin=origin)})


@record(kw_only=True)
class TransformFrame(TransformLink):
    """Move only the frame of `link`: its children, visuals, collisions and inertial stay put.

    X_PL' = X_PL · T, and everything given in L is re-expressed: X_L'V = T⁻¹ · X_LV, for
    visuals, collisions, the inertial and child joints; the axis of L's joint turns with
    it, so the motion — and the dynamics — are unchanged.
    """

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        parent = parent_joint(robot).get(self.link)
        if parent is not None and parent.type in ("revolute", "continuous"):
            import numpy as np

            a = np.asarray(parent.axis or (1.0, 0.0, 0.0), dtype=float)
            p = np.asarray(self.xyz, dtype=float)
            if np.linalg.norm(np.cross(a / np.linalg.norm(a), p)) > 1e-12:
                effects.error("E0320", f"transform_frame of '{self.link}' would move the axis of "
                              f"{parent.type} joint '{parent.name}' off its line and change the motion; "
                              "translate the frame only along the axis", "link")
                return robot
        return move_frame(robot, self.link, Pose(self.xyz, self.rpy))


def move_frame(robot: Robot, link_name: str, T: Pose) -> Robot:
    """X_PL' = X_PL · T with everything given in L re-expressed (X_L'V = T⁻¹ · X_LV), and the
    axis of L's joint turned with the frame."""
    from mpc.ir.kinematics import compose_poses, inverse_pose, pose_matrix

    T_inv = inverse_pose(T)
    R_inv = pose_matrix(T_inv)[:3, :3]
    joints = dict(robot.joints)
    parent = parent_joint(robot).get(link_name)
    if parent is not None:
        axis = parent.axis
        if axis is not None or parent.type not in ("fixed", "floating"):
            axis = tuple(float(x) for x in R_inv @ (axis or (1.0, 0.0, 0.0)))
        joints[parent.name] = replace(parent, origin=compose_poses(parent.origin, T),
                                      axis=axis)
    for name, j in robot.joints.items():
        if j.parent == link_name:
            joints[name] = replace(j, origin=compose_poses(T_inv, j.origin))
    link = robot.links[link_name]
    inertial = link.inertial
    link = replace(
        link,
        inertial=inertial and replace(inertial, origin=compose_poses(T_inv, inertial.origin)),
        visuals=tuple(replace(v, origin=compose_poses(T_inv, v.origin)) for v in link.visuals),
        collisions=tuple(replace(c, origin=compose_poses(T_inv, c.origin)) for c in link.collisions))
    return replace(robot, joints=joints, links={**robot.links, link_name: link})


@record(kw_only=True)
class ReparentLink(Op):
    """Hang `link` below `parent`, keeping its pose in the root frame (at q = 0)."""

    PHASE = Phase.FRAMES

    WHAT = "reparent_to"

    link: LinkRef
    parent: LinkRef

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

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """X_NL = X_RN⁻¹ · X_RL: L keeps its pose in the root frame R under its new parent N."""
        from mpc.ir import transforms as tf
        from mpc.ir.kinematics import link_in_root, matrix_pose

        joint = parent_joint(robot)[self.link]
        X_NL = matrix_pose(tf.inverse(link_in_root(robot, self.parent)) @ link_in_root(robot, self.link))
        moved = replace(joint, parent=self.parent, origin=X_NL)
        return replace(robot, joints={**robot.joints, joint.name: moved})


@record(kw_only=True)
class EstimateMissingComs(Op):
    """Set the COM of each of `links` (all when empty) whose COM is at its origin, from its
    collision geometry."""

    PHASE = Phase.FRAMES

    WHAT = "estimate_missing_coms"

    links: tuple[LinkRef, ...] = ()

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The COM of a link whose COM is at its origin becomes the centre of volume of the
        solid union of its collision shapes (uniform density, overlaps counted once); the
        inertia tensor is kept."""
        links = dict(robot.links)
        for name in self.links or tuple(robot.links):
            link = links[name]
            inertial = link.inertial
            if inertial is None or not link.collisions or (
                    inertial.origin is not None and any(inertial.origin.xyz)):
                continue
            whole = collision_solid(self, name, link.collisions, effects)
            if whole is None or whole.props.mass <= 0:
                continue
            com = tuple(float(x) for x in whole.props.com)
            origin = replace(inertial.origin or Pose(), xyz=com, written=(True, True))
            links[name] = replace(link, inertial=replace(inertial, origin=origin))
        return replace(robot, links=links)


@record(kw_only=True)
class EstimateMissingInertia(Op):
    """Fill the inertia tensor of each of `links` (all when empty) that has a mass and a
    missing or zero inertia, from its collision geometry."""

    PHASE = Phase.FRAMES

    WHAT = "estimate_missing_inertia"

    links: tuple[LinkRef, ...] = ()

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """The inertia becomes the union's (uniform density) scaled to the link's mass, about
        the union's centre of volume, turned into the inertial frame; the COM is kept."""
        from mpc.ir.kinematics import pose_matrix

        links = dict(robot.links)
        for name in self.links or tuple(robot.links):
            link = links[name]
            inertial = link.inertial
            if inertial is None or inertial.mass <= 0 or not link.collisions or any(
                    getattr(inertial.inertia, k) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")):
                continue
            whole = collision_solid(self, name, link.collisions, effects)
            if whole is None or whole.props.mass <= 0:
                continue
            R = pose_matrix(inertial.origin or Pose())[:3, :3]
            I_C = R.T @ whole.props.I @ R * (inertial.mass / whole.props.mass)
            values = {k: float(I_C[a, b]) for k, (a, b) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)),
                                                        ("iyy", (1, 1)), ("iyz", (1, 2)), ("izz", (2, 2)))}
            links[name] = replace(link, inertial=replace(inertial, inertia=Inertia(**values)))
        return replace(robot, links=links)


def collision_solid(op: Op, link: str, collisions: Sequence[Collision], effects: Effects,
                    field: str = "links") -> Solid | None:
    """The solid union of a link's collisions in the link frame (ir/solids.py); warns about
    convex-hull stand-ins (W0580) and repaired meshes (W0581) at the op's `field`; None after
    an unreadable mesh (E0602)."""
    from mpc.ir.kinematics import pose_matrix
    from mpc.ir.mesh_props import MeshError, solid
    from mpc.ir.solids import union

    try:
        whole = union([(solid(c.geometry), pose_matrix(c.origin)) for c in collisions])
    except MeshError as e:
        effects.error("E0602", f"{op.what()} of link '{link}': {e}", field)
        return None
    for code, note in whole.notes:
        effects.sink.warning(op.span_of(field), code, f"{op.what()} of link '{link}': {note}")
    return whole


@record(kw_only=True)
class AnnotateLinks(Op):
    """Free annotations (for SMURF) on `links` (all when empty); material: set the visuals'."""

    PHASE = Phase.FRAMES

    WHAT = "frames"

    links: tuple[LinkRef, ...] = ()
    material: MaterialRef | None = None
    annotations: Annotations = field(default_factory=dict)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        links = dict(robot.links)
        for name in self.links or tuple(robot.links):
            link = links[name]
            visuals = link.visuals
            if self.material is not None:
                visuals = tuple(replace(v, material=self.material, inline_material=None) for v in visuals)
            links[name] = replace(link, visuals=visuals,
                                  annotations={**link.annotations, **self.annotations})
        return replace(robot, links=links)
