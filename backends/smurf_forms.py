"""Phobos's SMURF value forms ↔ mpc's values: colours, offsets, the names Phobos gives
unnamed visuals and collisions, the material keys SMURF holds and URDF does not, and what a
motor takes from its joint. Shared by the SMURF writer and reader; no file access.

Phobos 2.x writes a colour as `{r, g, b, a}` (older releases: a list), a sensor's
position_offset as `{x, y, z}` and its orientation_offset as a quaternion `{x, y, z, w}`
(older: lists). mpc reads every form and writes the mapping forms. An unnamed shape is
named as Phobos's `Link` names it: `<link>_collision` / `<link>_visual`, and the k-th
repetition of a name in one link gets `k` appended (`<link>_collision1`, …).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from mpc.ir.robot import Link, Robot

# Material fields SMURF holds and URDF does not, with their SMURF (MARS) key.
MATERIAL_COLOURS = (("ambient", "ambientColor"), ("specular", "specularColor"), ("emissive", "emissionColor"))
MATERIAL_SCALARS = ("shininess", "transparency", "normal_texture")
MOTOR_TYPE = "position"  # Phobos's default control type of a motor


def number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def floats(value: Any, sizes: tuple[int, ...]) -> tuple[float, ...] | None:
    """A list of `sizes` numbers as floats, else None."""
    if isinstance(value, list) and len(value) in sizes and all(number(v) for v in value):
        return tuple(float(v) for v in value)
    return None


def _keyed(value: Any, keys: str) -> tuple[float, ...] | None:
    if isinstance(value, dict) and set(value) == set(keys) and all(number(value[k]) for k in keys):
        return tuple(float(value[k]) for k in keys)
    return None


def colour_out(values: Sequence[float]) -> dict[str, float]:
    return dict(zip("rgba", values, strict=False))


def colour_in(value: Any, sizes: tuple[int, ...] = (3, 4)) -> tuple[float, ...] | None:
    """`{r, g, b[, a]}` or `[r, g, b[, a]]` → the numbers; None when it is neither."""
    if isinstance(value, dict):
        return _keyed(value, "rgba"[:len(value)]) if len(value) in sizes else None
    return floats(value, sizes)


def position_out(xyz: Sequence[float]) -> dict[str, float]:
    return dict(zip("xyz", xyz, strict=True))


def position_in(value: Any) -> tuple[float, ...] | None:
    """`{x, y, z}` or `[x, y, z]`."""
    return _keyed(value, "xyz") if isinstance(value, dict) else floats(value, (3,))


def orientation_out(values: Sequence[float]) -> dict[str, float]:
    """rpy as `{r, p, y}` (Phobos's Pose reads that form), a quaternion as `{x, y, z, w}`."""
    return dict(zip("rpy" if len(values) == 3 else "xyzw", values, strict=True))


def orientation_in(value: Any) -> tuple[float, ...] | None:
    """`{r, p, y}`, `{x, y, z, w}` (in any key order) or a list of 3 (rpy) or 4 (x, y, z, w)."""
    if isinstance(value, dict):
        return _keyed(value, "rpy") if len(value) == 3 else _keyed(value, "xyzw")
    return floats(value, (3, 4))


def shape_names(link: str, kind: str, names: Sequence[str | None]) -> list[str]:
    """The names Phobos gives the `kind` ("collision", "visual") shapes of `link`, in order.

    A shape an SDF named `<link>_<kind>_<i>` after its place `i` counts as unnamed (mpc's SDF
    writer names unnamed shapes so), so a SMURF finds it whichever model file it links."""
    base = f"{link}_{kind}"
    seen: dict[str, int] = {}
    out = []
    for i, name in enumerate(names):
        if name is None or name == f"{base}_{i}":
            name = base
        if name in seen:
            seen[name] += 1
            name = f"{name}{seen[name]}"
        else:
            seen[name] = 0
        out.append(name)
    return out


def named_shapes(robot: Robot) -> Robot:
    """`robot` with every unnamed visual and collision named as the SMURF names it
    (`shape_names`), so that each name a SMURF's files hold names an element of the model
    file it links: Phobos finds a shape's annotations by that name. A link whose shapes all
    have names already is left as it is (and so is the robot when every link is)."""
    links: dict[str, Link] = {}
    for link in robot.links.values():
        changes: dict[str, tuple[Any, ...]] = {}
        for kind in ("visual", "collision"):
            shapes = getattr(link, f"{kind}s")
            if any(s.name is None for s in shapes):
                names = shape_names(link.name, kind, [s.name for s in shapes])
                changes[f"{kind}s"] = tuple(s if s.name is not None else dataclasses.replace(s, name=n)
                                            for s, n in zip(shapes, names, strict=True))
        if changes:
            links[link.name] = dataclasses.replace(link, **changes)
    if not links:
        return robot
    return dataclasses.replace(robot, links={**robot.links, **links})


def motor_limits(robot: Robot, joint: str) -> dict[str, float]:
    """maxEffort, maxSpeed, maxValue and minValue of a motor: its joint's limits (Phobos)."""
    j = robot.joints.get(joint)
    limit = j.limit if j is not None else None
    if limit is None:
        return {}
    values = {"maxEffort": limit.effort, "maxSpeed": limit.velocity, "maxValue": limit.upper,
              "minValue": limit.lower}
    return {k: v for k, v in values.items() if v is not None}
