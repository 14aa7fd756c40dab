"""Facts of the SMURF format that its writer (backends/smurf.py) and reader
(backends/smurf_reader.py) share: the material keys SMURF holds and URDF does not, and the
limits a motor takes from its joint. No I/O here.
"""

from __future__ import annotations

from mpc.ir.robot import Robot

# Material fields SMURF holds and URDF does not, with their SMURF (MARS) key.
MATERIAL_COLOURS = (("ambient", "ambientColor"), ("specular", "specularColor"), ("emissive", "emissionColor"))
MATERIAL_SCALARS = ("shininess", "transparency", "normal_texture")


def motor_limits(robot: Robot, joint: str) -> dict[str, float]:
    """maxEffort, maxSpeed, maxValue and minValue of a motor: its joint's limits (Phobos)."""
    j = robot.joints.get(joint)
    limit = j.limit if j is not None else None
    if limit is None:
        return {}
    values = {"maxEffort": limit.effort, "maxSpeed": limit.velocity, "maxValue": limit.upper,
              "minValue": limit.lower}
    return {k: v for k, v in values.items() if v is not None}
