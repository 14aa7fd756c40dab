"""The robot value: links, joints and materials keyed by name, plus opaque fragments.

All classes are frozen; a derived robot shares every element it did not change
(`dataclasses.replace`). Optional URDF attributes are None when the source did not
write them, so that a model is written back the way it was read.

Fields common to several elements:
- span: where the element was read from (None for elements mpc created).
- comments: XML comments that stood right before the element.
- inner_comments: XML comments inside the element (written back at its top).
- extra_attrs: attributes URDF does not define, kept as (name, value) pairs.
- extras: child elements URDF does not define, kept as opaque fragments.
- annotations: free data from the definition (for SMURF), never written to URDF.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any, Literal

from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.fragments import Fragment
from mpc.ir.geometry import Attrs, Geometry, Vec3
from mpc.ir.refs import (
    CollisionName,
    JointName,
    JointRef,
    LinkName,
    LinkRef,
    MaterialName,
    MaterialRef,
    PoseName,
    VisualName,
)

JointType = Literal["revolute", "continuous", "prismatic", "fixed", "floating", "planar"]
JOINT_TYPES: tuple[str, ...] = JointType.__args__

ZERO: Vec3 = (0.0, 0.0, 0.0)


@record(slots=True, bulk=True)
class Pose:
    """X_PC as URDF writes it: origin of C in P (xyz, metres) and fixed-axis rpy (radians).

    written: which of the two attributes the source wrote, so an absent rpy stays absent.
    """

    xyz: Vec3 = ZERO
    rpy: Vec3 = ZERO
    written: tuple[bool, bool] = (True, True)


IDENTITY = Pose(written=(False, False))


@record(slots=True, kw_only=True, bulk=True)
class Inertia:
    """The rotational inertia about the COM, in the inertial frame (kg·m²)."""

    ixx: float
    ixy: float
    ixz: float
    iyy: float
    iyz: float
    izz: float


@record(slots=True, kw_only=True, bulk=True)
class Inertial:
    """Mass properties: origin is the COM frame in the link frame; mass in kg."""

    mass: float
    inertia: Inertia
    origin: Pose | None = None
    extras: tuple[Fragment, ...] = ()


@record(slots=True, kw_only=True, bulk=True)
class Material:
    """A named material: rgba colour (0..1 each) and/or a texture filename.

    texture: "" for a `<texture/>` without filename (iCub writes those), None for none.
    """

    name: MaterialName
    rgba: tuple[float, float, float, float] | None = None
    texture: str | None = None
    ambient: tuple[float, ...] | None = None
    specular: tuple[float, ...] | None = None
    emissive: tuple[float, ...] | None = None
    shininess: float | None = None
    transparency: float | None = None
    normal_texture: str | None = None
    annotations: Mapping[str, object] = field(default_factory=dict)
    comments: tuple[str, ...] = ()
    span: Span | None = None


@record(slots=True, kw_only=True, bulk=True)
class Visual:
    """A visual shape of a link.

    material: the name of the material, or None.
    inline_material: the material as defined inside this visual, when it was.
    """

    geometry: Geometry
    name: VisualName | None = None
    origin: Pose | None = None
    material: MaterialRef | None = None
    inline_material: Material | None = None
    geometry_attrs: Attrs = ()
    extra_attrs: Attrs = ()
    extras: tuple[Fragment, ...] = ()
    annotations: Mapping[str, object] = field(default_factory=dict)
    span: Span | None = None


@record(slots=True, kw_only=True, bulk=True)
class Collision:
    """A collision shape of a link."""

    geometry: Geometry
    name: CollisionName | None = None
    origin: Pose | None = None
    geometry_attrs: Attrs = ()
    extra_attrs: Attrs = ()
    extras: tuple[Fragment, ...] = ()
    bitmask: int | None = None
    annotations: Mapping[str, object] = field(default_factory=dict)
    span: Span | None = None


@record(slots=True, kw_only=True, bulk=True)
class Link:
    """A rigid body. visuals and collisions keep their source order."""

    name: LinkName
    inertial: Inertial | None = None
    visuals: tuple[Visual, ...] = ()
    collisions: tuple[Collision, ...] = ()
    extra_attrs: Attrs = ()
    extras: tuple[Fragment, ...] = ()
    annotations: Mapping[str, object] = field(default_factory=dict)
    comments: tuple[str, ...] = ()
    inner_comments: tuple[str, ...] = ()
    span: Span | None = None


@record(slots=True, kw_only=True, bulk=True)
class Limit:
    """Joint limits: position (lower, upper; rad or m), effort (N·m or N), velocity."""

    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    extra_attrs: Attrs = ()


@record(slots=True, kw_only=True, bulk=True)
class Dynamics:
    """Viscous damping and Coulomb friction of a joint."""

    damping: float | None = None
    friction: float | None = None
    extra_attrs: Attrs = ()


@record(slots=True, kw_only=True, bulk=True)
class Mimic:
    """This joint follows `joint`: q = multiplier · q_joint + offset."""

    joint: JointRef
    multiplier: float | None = None
    offset: float | None = None


@record(slots=True, kw_only=True, bulk=True)
class Calibration:
    """Reference positions of the joint's calibration switches."""

    rising: float | None = None
    falling: float | None = None
    reference_position: float | None = None


@record(slots=True, kw_only=True, bulk=True)
class SafetyController:
    """Soft limits and gains of the joint's safety controller."""

    k_velocity: float
    k_position: float | None = None
    soft_lower_limit: float | None = None
    soft_upper_limit: float | None = None


@record(slots=True, kw_only=True, bulk=True)
class Joint:
    """A joint from `parent` to `child`; origin is X_PJ, the joint frame in the parent.

    axis: the joint axis in the joint frame, or None when not written (URDF: 1 0 0).
    """

    name: JointName
    type: JointType
    parent: LinkRef
    child: LinkRef
    origin: Pose | None = None
    axis: Vec3 | None = None
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    mimic: Mimic | None = None
    calibration: Calibration | None = None
    safety_controller: SafetyController | None = None
    extra_attrs: Attrs = ()
    extras: tuple[Fragment, ...] = ()
    annotations: Mapping[str, object] = field(default_factory=dict)
    comments: tuple[str, ...] = ()
    inner_comments: tuple[str, ...] = ()
    span: Span | None = None


@record(slots=True, kw_only=True, bulk=True)
class Robot:
    """A robot model: a tree of links connected by joints.

    name: the robot's name.
    root: the root link's name.
    links, joints, materials: elements keyed by name (mappings are never mutated).
    fragments: top-level elements mpc does not model, in source order.
    motors, sensors, cut_joints: by name (ir/extras.py). poses: named joint configurations.
    submechanisms: in definition order; submechanisms_file: used as it is, when given.
    annotations: named annotation categories.
    submodel_definitions: the `<name>_submodels.yml` of a SMURF it was read from, by submodel.
    extra_attrs: attributes of `<robot>` other than name (namespaces, version).
    header_comments: comments before `<robot>`; trailing_comments: at its end.
    """

    name: str
    root: LinkRef
    links: Mapping[LinkName, Link]
    joints: Mapping[JointName, Joint]
    materials: Mapping[str, Material] = field(default_factory=dict)
    fragments: tuple[Fragment, ...] = ()
    extra_attrs: Attrs = ()
    header_comments: tuple[str, ...] = ()
    trailing_comments: tuple[str, ...] = ()
    motors: Mapping[str, Any] = field(default_factory=dict)
    sensors: Mapping[str, Any] = field(default_factory=dict)
    cut_joints: Mapping[str, Any] = field(default_factory=dict)
    poses: Mapping[PoseName, Mapping[JointRef, float]] = field(default_factory=dict)
    submechanisms: tuple[Any, ...] = ()
    submechanisms_file: str | None = None
    annotations: Mapping[str, Mapping[str, object]] = field(default_factory=dict)
    span: Span | None = None
    submodel_definitions: Mapping[str, object] = field(default_factory=dict)
