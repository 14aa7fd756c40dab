"""physical_validity (always run): is each link physically possible?

- every movable joint carries mass > 0: its child or a link beyond it (a massless link between
  two joints of a 2- or 3-DoF joint is fine; a joint that moves nothing makes the mass
  matrix singular);
- each inertia tensor (mass > 0) is positive definite and its principal moments satisfy the
  triangle inequality A + B ≥ C, with a tolerance relative to the largest moment (1e-6:
  what the six written digits of a URDF inertia can carry);
- the COM lies inside the bounding box of the link's collision shapes (grown by `distance`);
- a link with collision shapes has mass.

Findings are warnings (W0701, the test passes) unless the test is listed as
`- physical_validity: error`, which makes them failures.
"""

from __future__ import annotations

import numpy as np

from mpc.checks.protocol import Result, failed, first_of, passed, vector_text
from mpc.checks.registry import Context, register
from mpc.checks.topology import MOVABLE
from mpc.ir.geometry import Box, Cylinder, Geometry, Sphere
from mpc.ir.kinematics import pose_matrix
from mpc.ir.program import ModelTest
from mpc.ir.robot import Inertia, Robot
from mpc.ir.span import Span
from mpc.ir.tree import child_joints

RELATIVE = 1e-6


def principal_moments(i: Inertia) -> np.ndarray:
    matrix = np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])
    return np.linalg.eigvalsh(matrix)


def inertia_problem(i: Inertia) -> str:
    """Why an inertia tensor is impossible, or ""."""
    moments = principal_moments(i)
    scale = max(float(np.max(np.abs(moments))), 1e-300)
    if moments[0] <= 0:
        return f"inertia is not positive definite (principal moments {vector_text(moments)})"
    a, b, c = moments  # ascending: only a + b ≥ c can fail
    if a + b < c - RELATIVE * scale:
        return (f"principal moments {vector_text(moments)} violate the triangle inequality: "
                f"{a:.4g} + {b:.4g} < {c:.4g}")
    return ""


def _corners(geometry: Geometry) -> np.ndarray | None:
    """The corners of the shape's bounding box in its own frame (8×3), or None (unreadable)."""
    if isinstance(geometry, Box):
        lo, hi = -np.asarray(geometry.size) / 2, np.asarray(geometry.size) / 2
    elif isinstance(geometry, Cylinder):
        r, h = geometry.radius, geometry.length / 2
        lo, hi = np.array([-r, -r, -h]), np.array([r, r, h])
    elif isinstance(geometry, Sphere):
        lo, hi = -np.full(3, geometry.radius), np.full(3, geometry.radius)
    else:
        from mpc.ir.mesh_props import MeshError, as_trimesh

        try:
            lo, hi = as_trimesh(geometry).bounds
        except MeshError:
            return None
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def collision_box(robot: Robot, link: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The axis-aligned bounding box of the link's collision shapes in the link frame."""
    points = []
    for c in robot.links[link].collisions:
        corners = _corners(c.geometry)
        if corners is None:
            return None
        X = pose_matrix(c.origin)
        points.append(corners @ X[:3, :3].T + X[:3, 3])
    if not points:
        return None
    allp = np.vstack(points)
    return allp.min(axis=0), allp.max(axis=0)


def findings(robot: Robot, distance: float) -> list[tuple[str, str]]:
    """(link, problem) for every finding, in link order."""
    out: list[tuple[str, str]] = []
    children = child_joints(robot)

    def carried_mass(link: str) -> float:
        """The mass of the link and of every link beyond it (each link once, should the
        joints not form a tree)."""
        total, todo, seen = 0.0, [link], {link}
        while todo:
            at = todo.pop()
            inertial = robot.links[at].inertial
            total += max(inertial.mass, 0.0) if inertial else 0.0
            for j in children.get(at, []):
                if j.child in robot.links and j.child not in seen:
                    seen.add(j.child)
                    todo.append(j.child)
        return total

    for joint in sorted(robot.joints.values(), key=lambda j: j.name):
        if joint.type in MOVABLE and joint.child in robot.links and carried_mass(joint.child) <= 0:
            out.append((joint.child, f"moves with joint '{joint.name}' but neither it nor a link "
                                     "beyond it has mass"))
    for name in sorted(robot.links):
        link = robot.links[name]
        inertial = link.inertial
        mass = inertial.mass if inertial else 0.0
        if mass < 0:
            out.append((name, f"mass {mass:g} kg is negative"))
            continue
        if mass == 0:
            if link.collisions:
                out.append((name, "has collision shapes but no mass"))
            continue
        assert inertial is not None
        problem = inertia_problem(inertial.inertia)
        if problem:
            out.append((name, problem))
        box = collision_box(robot, name)
        if box is not None:
            com = np.asarray(inertial.origin.xyz if inertial.origin else (0.0, 0.0, 0.0))
            lo, hi = box
            outside = float(np.max(np.maximum(lo - com, com - hi)))
            if outside > distance:
                out.append((name, f"COM {vector_text(com)} m lies {outside:.4g} m outside the collision "
                                  f"bounding box {vector_text(lo)}…{vector_text(hi)} m"))
    return out


@register("physical_validity")
def physical_validity(ctx: Context, test: ModelTest) -> Result:
    robot = ctx.built.robot
    found = findings(robot, ctx.tol.distance)
    details = tuple(f"{link}: {problem}" for link, problem in found)
    figure = float(len(found))
    if not found:
        return passed(test.name, f"{len(robot.links)} links: masses, inertias and COMs are possible",
                      figure=0.0, unit="findings", tolerances=ctx.bound("distance", "m"))
    first = first_of([f"link '{link}' {problem}" for link, problem in found])
    if test.as_error:
        return failed(test.name, first, figure=figure, unit="findings", tolerances=ctx.bound("distance", "m"),
                      details=details)
    for link, problem in found:
        span = robot.links[link].span or Span.of_file(str(ctx.built.path))
        ctx.sink.warning(span, "W0701", f"link '{link}' {problem}")
    return passed(test.name, f"{len(found)} warnings: {first}", figure=figure, unit="findings",
                  tolerances=ctx.bound("distance", "m"), details=details)

