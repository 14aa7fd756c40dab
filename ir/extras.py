"""Model data beyond URDF's: motors, sensors, loop-closure joints, submechanisms.

They travel with the robot value and are written by the formats that can hold them
(SMURF, SDF, MJCF); a URDF export says which of them it leaves out.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field

from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.refs import JointRef, LinkOrJointRef, LinkRef, MotorName, SensorName, SubmechanismName
from mpc.ir.robot import Pose

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


@record(slots=True, kw_only=True)
class Motor:
    """A motor driving `joint`; settings: controller gains and limits as written (p, i, d, …)."""

    name: MotorName
    joint: JointRef
    settings: Annotations = field(default_factory=dict)


@record(slots=True, kw_only=True)
class Sensor:
    """A sensor of `type` on `link` (or `joint`), or over `targets` (joints or links)."""

    name: SensorName
    type: str
    link: LinkRef | None = None
    joint: JointRef | None = None
    frame: LinkRef | None = None
    targets: tuple[LinkOrJointRef, ...] = ()
    position_offset: Vec3 | None = None
    orientation_offset: tuple[float, ...] | None = None
    annotations: Annotations = field(default_factory=dict)


@record(slots=True, kw_only=True)
class CutJoint:
    """A loop-closure joint between two links of the tree (not part of the tree).

    origin: X_PC, the child link in the parent link at the zero configuration.
    constraint_axes: (name, axis) of each constrained direction.
    """

    name: str
    type: str
    parent: LinkRef
    child: LinkRef
    origin: Pose
    constraint_axes: tuple[tuple[str | None, Vec3], ...] = ()
    annotations: Annotations = field(default_factory=dict)
    span: Span | None = None


@record(slots=True, kw_only=True)
class Submechanism:
    """A submechanism or exoskeleton (HyRoDyn's terms): its definition as written."""

    name: SubmechanismName
    exoskeleton: bool = False
    definition: Annotations = field(default_factory=dict)
