"""Plausibility of the compiled model on its own: effort_covers_gravity (Pinocchio) and
self_collision (coal).

Both look at the same configurations, in this order: q = 0, then each named pose of the
definition (`poses`, joints it does not name at 0; with loops the loops are closed).

effort_covers_gravity: for each actuated joint with an effort limit, its range is sampled at
SAMPLES evenly spaced values from lower to upper, both included (a continuous joint, or one
without limits: SAMPLES - 1 values over a whole turn from -π), with the rest of the robot
held at each configuration; the worst |gravity torque| (fixed base, gravity -9.81 m/s² along
the root's z) is compared with the effort limit. The rest of the robot is not searched for
its worst posture: name a pose that loads the joints most (the arm stretched out) to have it
judged. The sampling is fixed, so the figures are the same on every run.

self_collision: the collision shapes of two links are tested when the definition gives them
bitmasks that share a bit; with no bitmask in the definition, when the links are not kept
apart by the kinematic rules (ir/bitmask.py: a link and its parent, and its ancestors above
it while the joints in between only rotate).
"""

from __future__ import annotations

from itertools import combinations
from typing import Any

import numpy as np

from mpc.checks.dynamics_model import DynamicsError
from mpc.checks.protocol import Result, counted, failed, first_of, passed, verdict
from mpc.checks.registry import Context, register
from mpc.ir.geometry import Box, Geometry, Mesh, Sphere
from mpc.ir.program import ModelTest
from mpc.ir.robot import Collision, Robot

SAMPLES = 17


def configurations(robot: Robot) -> list[tuple[str, dict[str, float]]]:
    """The configurations both tests look at: q = 0 and each named pose, with their names."""
    out: list[tuple[str, dict[str, float]]] = [("q = 0", {})]
    out += [(f"pose '{name}'", {str(j): float(v) for j, v in values.items()})
            for name, values in robot.poses.items()]
    return out


def samples(robot: Robot, joint: str) -> np.ndarray:
    """The values of `joint` at which its gravity torque is taken (see the module's docstring)."""
    j = robot.joints[joint]
    limit = j.limit
    if j.type != "continuous" and limit is not None and limit.lower is not None and limit.upper is not None \
            and limit.lower <= limit.upper:
        return np.linspace(limit.lower, limit.upper, SAMPLES)
    if j.type == "prismatic":
        return np.zeros(1)
    return np.linspace(-np.pi, np.pi, SAMPLES - 1, endpoint=False)


def _dynamics(ctx: Context, name: str) -> tuple[Any, Result | None]:
    try:
        return ctx.built.dynamics(), None
    except DynamicsError as e:
        return None, failed(name, f"the compiled model does not load in Pinocchio: {e}")


@register("effort_covers_gravity")
def effort_covers_gravity(ctx: Context, test: ModelTest) -> Result:
    """Each actuated joint's worst gravity torque over its sampled range ≤ its effort limit.
    The figure is the worst ratio |τ| / effort."""
    dyn, problem = _dynamics(ctx, test.name)
    if problem is not None:
        return problem
    robot = ctx.built.robot
    configs = configurations(robot)
    unlimited: list[str] = []
    rows: list[tuple[float, str]] = []
    for joint in dyn.actuated:
        j = robot.joints.get(joint)
        if j is None or j.type not in ("revolute", "continuous", "prismatic"):
            continue
        effort = j.limit.effort if j.limit is not None else None
        if not effort or effort <= 0:
            unlimited.append(joint)
            continue
        worst, at = -1.0, ""  # the first sample sets both
        for label, values in configs:
            for value in samples(robot, joint):
                try:
                    q = dyn.configuration({**values, joint: float(value)})
                    torque = abs(dyn.gravity_torques(q, (joint,) if not dyn.constraints else None)[joint])
                except DynamicsError as e:
                    return failed(test.name, f"joint '{joint}' at {value:.4g} ({label}): {e}")
                if torque > worst + 1e-12:
                    worst, at = torque, f"{joint} = {value:.4g}, {label}"
        unit = "N" if j.type == "prismatic" else "N·m"
        rows.append((worst / effort, f"joint '{joint}': gravity {worst:.4g} {unit} at {at}, "
                                     f"effort limit {effort:g} {unit}"))
    rows.sort(key=lambda r: -r[0])
    over = [f"{text} (×{ratio:.3g})" for ratio, text in rows if ratio > 1.0]
    note = (f"no effort limit: {', '.join(repr(n) for n in unlimited)}",) if unlimited else ()
    if not rows:
        return passed(test.name, "no actuated joint has an effort limit", details=note)
    worst_ratio = rows[0][0]
    holds = "holds itself over its range" if len(rows) == 1 else "hold themselves over their ranges"
    reason = first_of(over) if over else (f"{counted(len(rows), 'joint')} {holds} in "
                                          f"{counted(len(configs), 'configuration')}; the most loaded: "
                                          f"{rows[0][1]}")
    details = tuple(over or [text for _, text in rows[:5]]) + note
    return verdict(test.name, not over, reason, figure=float(worst_ratio), unit="of the effort limit",
                   details=details)


def _bitmasks(ctx: Context) -> dict[tuple[str, int], int]:
    """The definition's bitmask of each collision, by link and index (the written model lacks
    them: URDF has no bitmask)."""
    out: dict[tuple[str, int], int] = {}
    source = ctx.robot
    if source is None:
        return out
    for name, link in source.links.items():
        built = ctx.built.robot.links.get(name)
        if built is None or len(built.collisions) != len(link.collisions):
            continue
        for i, c in enumerate(link.collisions):
            if c.bitmask is not None:
                out[(name, i)] = c.bitmask
    return out


def tested_pairs(robot: Robot, bitmasks: dict[tuple[str, int], int]
                 ) -> list[tuple[tuple[str, int], tuple[str, int]]]:
    """The pairs of collisions (link, index) on different links that self_collision tests."""
    from mpc.ir.bitmask import never_colliding

    shapes = [(n, i) for n, link in robot.links.items() for i in range(len(link.collisions))]
    apart = set() if bitmasks else never_colliding(robot)
    out = []
    for a, b in combinations(shapes, 2):
        if a[0] == b[0]:
            continue
        if bitmasks:
            if bitmasks.get(a, 0) & bitmasks.get(b, 0):
                out.append((a, b))
        elif frozenset((a[0], b[0])) not in apart:
            out.append((a, b))
    return out


class _Shapes:
    """The collision shapes: their bounding boxes in their own frame, and their coal objects,
    made only for a pair whose boxes overlap (a mesh's BVH costs more than testing it); each
    mesh file read once."""

    def __init__(self) -> None:
        self.meshes: dict[object, Any] = {}
        self.made: dict[object, Any] = {}

    @staticmethod
    def _key(geometry: Geometry) -> object:
        if isinstance(geometry, Mesh):
            return geometry.source.path, geometry.scale, geometry.ops
        return geometry

    def _mesh(self, geometry: Mesh) -> Any:
        from mpc.ir.bitmask import mesh_triangles

        key = self._key(geometry)
        if key not in self.meshes:
            self.meshes[key] = mesh_triangles(geometry)
        return self.meshes[key]

    def corners(self, geometry: Geometry) -> np.ndarray:
        """The 8 corners of the shape's bounding box in its frame (4×8, homogeneous)."""
        if isinstance(geometry, Mesh):
            vertices, faces = self._mesh(geometry)
            used = vertices[faces.reshape(-1)]  # trimesh's bounds: of the vertices triangles use
            lo, hi = used.min(axis=0), used.max(axis=0)
        else:
            if isinstance(geometry, Box):
                half = np.asarray(geometry.size, dtype=float) / 2
            elif isinstance(geometry, Sphere):
                half = np.full(3, geometry.radius)
            else:
                half = np.array([geometry.radius, geometry.radius, geometry.length / 2])
            lo, hi = -half, half
        grid = np.meshgrid(*zip(lo, hi, strict=True), indexing="ij")
        return np.vstack([np.array(grid).reshape(3, 8), np.ones(8)])

    def get(self, geometry: Geometry) -> Any:
        from mpc.ir.bitmask import coal_object

        key = self._key(geometry)
        if key not in self.made:
            mesh = self._mesh(geometry) if isinstance(geometry, Mesh) else None
            self.made[key] = coal_object(geometry, mesh)
        return self.made[key]


def _label(collision: Collision, index: int) -> str:
    return f"'{collision.name}'" if collision.name else f"#{index + 1}"


@register("self_collision")
def self_collision(ctx: Context, test: ModelTest) -> Result:
    """No two collision shapes that may collide overlap at q = 0 or at a named pose. The
    figure is the number of colliding pairs of links."""
    from mpc.ir.bitmask import overlap
    from mpc.ir.kinematics import pose_matrix

    robot = ctx.built.robot
    bitmasks = _bitmasks(ctx)
    pairs = tested_pairs(robot, bitmasks)
    if not pairs:
        return passed(test.name, "no two links' collision shapes may collide", figure=0.0, unit="pairs")
    dyn, problem = _dynamics(ctx, test.name)
    if problem is not None:
        return problem
    shapes = _Shapes()
    keys = sorted({k for pair in pairs for k in pair})
    geometry = {k: robot.links[k[0]].collisions[k[1]].geometry for k in keys}
    try:
        corners = {k: shapes.corners(geometry[k]) for k in keys}
    except Exception as e:  # a mesh that cannot be read: no verdict
        return failed(test.name, f"a collision mesh cannot be read: {e}")
    found: dict[frozenset[str], str] = {}
    configs = configurations(robot)
    for label, values in configs:
        try:
            placements = dyn.link_placements(dyn.configuration(values))
        except DynamicsError as e:
            return failed(test.name, f"{label}: {e}")
        where: dict[tuple[str, int], np.ndarray] = {}
        boxes: dict[tuple[str, int], tuple[np.ndarray, np.ndarray]] = {}
        for key in keys:
            X = placements[key[0]] @ pose_matrix(robot.links[key[0]].collisions[key[1]].origin)
            where[key] = X
            points = (X @ corners[key])[:3]
            boxes[key] = points.min(axis=1), points.max(axis=1)
        for a, b in pairs:
            links = frozenset((a[0], b[0]))
            if links in found or np.any(boxes[a][0] > boxes[b][1]) or np.any(boxes[b][0] > boxes[a][1]):
                continue
            try:
                oa, ob = shapes.get(geometry[a]), shapes.get(geometry[b])
            except Exception as e:
                return failed(test.name, f"a collision mesh cannot be read: {e}")
            if overlap(oa, where[a], ob, where[b]):
                ca, cb = robot.links[a[0]].collisions[a[1]], robot.links[b[0]].collisions[b[1]]
                found[links] = (f"links '{a[0]}' and '{b[0]}' collide at {label} (collisions "
                                f"{_label(ca, a[1])} and {_label(cb, b[1])})")
    problems = list(found.values())
    rule = "bitmasks" if bitmasks else "kinematic rules"
    return verdict(test.name, not problems, first_of(problems) if problems else
                   f"{counted(len(pairs), 'pair')} of collisions (by the {rule}) apart in "
                   f"{counted(len(configs), 'configuration')}",
                   figure=float(len(problems)), unit="pairs", details=tuple(problems))
