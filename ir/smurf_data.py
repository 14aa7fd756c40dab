"""A robot without its SMURF data (`inherit_smurf_properties: false` on a derived input).

SMURF data is what a SMURF holds beside the model file and the URDF cannot: motors,
sensors, poses, submechanisms (and a submechanisms file), annotation categories, and the
annotations and collision bitmasks of links, joints, visuals, collisions and materials.
What stays is the kinematic and physical model: links with their inertials and shapes,
joints, materials, loop-closure joints (SDF holds them too), and the fragments of the
model file.
"""

from __future__ import annotations

from dataclasses import replace

from mpc.ir.robot import Link, Robot


def _link(link: Link) -> Link:
    return replace(link, annotations={},
                   visuals=tuple(replace(v, annotations={}) for v in link.visuals),
                   collisions=tuple(replace(c, annotations={}, bitmask=None) for c in link.collisions))


def without_smurf_data(robot: Robot) -> Robot:
    """`robot` with no SMURF data (the module docstring lists it)."""
    return replace(
        robot, motors={}, sensors={}, poses={}, submechanisms=(), submechanisms_file=None, annotations={},
        submodel_definitions={},
        links={name: _link(link) for name, link in robot.links.items()},
        joints={name: replace(joint, annotations={}) for name, joint in robot.joints.items()},
        materials={name: replace(m, annotations={}) for name, m in robot.materials.items()})
