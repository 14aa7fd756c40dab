"""The scene file of an MJCF export (`scene: true`): `<robot>_scene.xml` beside the robot's,
which `<include>`s it and adds what Menagerie's scene.xml adds: a floor (the plane z = 0 of
the world, checkered), a directional light from above, a gradient sky and a camera position.

The floor collides with every collision geom that collides at all (contype = conaffinity =
every bit MuJoCo has, so a bitmask without MuJoCo's default bit still meets it). Its names
(`floor`, `groundplane`, `skybox`) get a suffix when the robot uses them.
"""

from __future__ import annotations

from mpc.backends import xml_escape
from mpc.ir.robot import Robot

__all__ = ["scene"]

ALL_BITS = str(2**31 - 1)  # contype and conaffinity are C ints


def _free(name: str, taken: set[str]) -> str:
    out, n = name, 1
    while out in taken:
        out, n = f"{name}_{n}", n + 1
    return out


def scene(robot: Robot, robot_file: str) -> str:
    """The scene's text; `robot_file`: the robot's MJCF, relative to the scene's folder."""
    taken = {*robot.links, *robot.materials,
             *(s.name for lk in robot.links.values() for s in (*lk.visuals, *lk.collisions) if s.name)}
    taken |= {m.name for lk in robot.links.values() for v in lk.visuals if (m := v.inline_material)}
    floor, ground, sky = (_free(n, taken) for n in ("floor", "groundplane", "skybox"))
    a = xml_escape.attribute
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
        f'    <geom name="{floor}" size="0 0 0.05" type="plane" material="{ground}" contype="{ALL_BITS}" '
        f'conaffinity="{ALL_BITS}"/>',
        "  </worldbody>",
        "</mujoco>",
        ""])
