"""The scene file of an MJCF export (`scene: true`): `<robot>_scene.xml` beside the robot's,
which `<include>`s it and adds what Menagerie's scene.xml adds: a checkered floor, a
directional light from above, a gradient sky and a camera position.

The floor is the horizontal plane through the lowest point of the robot's collision shapes
(its visuals when it has none) at q0, as MuJoCo places them (`floor_height`): a fixed-base
robot that reaches below its root (a humanoid hung at its pelvis) stands on it, and a
floating one starts on it rather than in it.

The floor collides with every collision geom that collides at all (contype = conaffinity =
every bit MuJoCo has, so a bitmask without MuJoCo's default bit still meets it). Its names
(`floor`, `groundplane`, `skybox`) get a suffix when the robot uses them.
"""

from __future__ import annotations

from pathlib import Path

from mpc.backends import xml_escape
from mpc.backends.xml import fmt_float
from mpc.core.names import free_name
from mpc.ir.robot import Robot

__all__ = ["floor_height", "scene"]

ALL_BITS = str(2**31 - 1)  # contype and conaffinity are C ints


def floor_height(robot_xml: Path, collision_group: int, said: list[str]) -> float:
    """The lowest z of the robot's collision geoms (group `collision_group`; all geoms when it
    has none) at q0, from MuJoCo's compiled model; 0 without geoms. ValueError (MuJoCo's
    message) when MuJoCo refuses the file; its warnings go to `said`."""
    import numpy as np

    from mpc.backends.mujoco_module import mujoco, warnings_into

    with warnings_into(said):
        model = mujoco.MjModel.from_xml_path(str(robot_xml))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    geoms = np.flatnonzero(model.geom_group == collision_group)
    if not len(geoms):
        geoms = np.arange(model.ngeom)
    if not len(geoms):
        return 0.0
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)

    def bottom(g: int) -> float:
        """A mesh's lowest vertex, a sphere's lowest point, else the lowest corner of the box
        around the shape in its frame."""
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            return float(data.geom_xpos[g][2] - model.geom_size[g][0])
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            m = model.geom_dataid[g]
            points = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
        else:
            points = model.geom_aabb[g, :3] + signs * model.geom_aabb[g, 3:]
        return float((data.geom_xpos[g] + points @ data.geom_xmat[g].reshape(3, 3).T)[:, 2].min())

    lowest = min(bottom(int(g)) for g in geoms)
    return 0.0 if abs(lowest) < 1e-12 else lowest


def scene(robot: Robot, robot_file: str, floor_z: float = 0.0) -> str:
    """The scene's text; `robot_file`: the robot's MJCF, relative to the scene's folder;
    `floor_z`: the floor's height."""
    taken = {*robot.links, *robot.materials,
             *(s.name for lk in robot.links.values() for s in (*lk.visuals, *lk.collisions) if s.name)}
    taken |= {m.name for lk in robot.links.values() for v in lk.visuals if (m := v.inline_material)}
    floor, ground, sky = (free_name(n, taken) for n in ("floor", "groundplane", "skybox"))
    a = xml_escape.attribute
    pos = f' pos="0 0 {fmt_float(floor_z)}"' if floor_z else ""
    return "\n".join([
        f'<mujoco model="{a(robot.name)} scene">',
        f'  <include file="{a(robot_file)}"/>',
        "  <visual>",
        '    <headlight diffuse="0.6 0.6 0.6" ambient="0.3 0.3 0.3" specular="0 0 0"/>',
        '    <rgba haze="0.15 0.25 0.35 1"/>',
        '    <global azimuth="120" elevation="-20"/>',
        "  </visual>",
        "  <asset>",
        f'    <texture name="{sky}" type="skybox" builtin="gradient" rgb1="0.3 0.5 0.7" rgb2="0 0 0" '
        'width="512" height="3072"/>',
        f'    <texture name="{ground}" type="2d" builtin="checker" mark="edge" rgb1="0.2 0.3 0.4" '
        'rgb2="0.1 0.2 0.3" markrgb="0.8 0.8 0.8" width="300" height="300"/>',
        f'    <material name="{ground}" texture="{ground}" texuniform="true" texrepeat="5 5" '
        'reflectance="0.2"/>',
        "  </asset>",
        "  <worldbody>",
        '    <light pos="0 0 1.5" dir="0 0 -1" directional="true"/>',
        f'    <geom name="{floor}"{pos} size="0 0 0.05" type="plane" material="{ground}" '
        f'contype="{ALL_BITS}" conaffinity="{ALL_BITS}"/>',
        "  </worldbody>",
        "</mujoco>",
        ""])
