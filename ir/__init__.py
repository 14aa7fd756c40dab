"""The robot IR: immutable robot values, transforms, fragments, ops and programs."""

from mpc.core.span import Span
from mpc.ir.fragments import Fragment, FragmentRef
from mpc.ir.geometry import Box, Cylinder, Geometry, Mesh, MeshSource, Sphere
from mpc.ir.robot import (
    Calibration,
    Collision,
    Dynamics,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mimic,
    Pose,
    Robot,
    SafetyController,
    Visual,
)

__all__ = [
    "Box", "Calibration", "Collision", "Cylinder", "Dynamics", "Fragment", "FragmentRef",
    "Geometry", "Inertia", "Inertial", "Joint", "Limit", "Link", "Material", "Mesh",
    "MeshSource", "Mimic", "Pose", "Robot", "SafetyController", "Span", "Sphere", "Visual",
]
