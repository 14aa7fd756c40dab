"""physical_validity (always run): is each link physically possible?

- every movable joint carries mass > 0: its child or a link beyond it (a massless link between
  two joints of a 2- or 3-DoF joint is fine; a joint that moves nothing makes the mass
  matrix singular);
- each inertia tensor (mass > 0) is positive definite and its principal moments satisfy the
  triangle inequality A + B ≥ C, with a tolerance relative to the largest moment (1e-6:
  what the six written digits of a URDF inertia can carry);
- the COM lies inside the bounding box of the link's collision shapes (grown by `distance`);
- a link with collision shapes has mass;
- plausibility, for each link whose collision shapes make a closed solid (their union,
  ir/solids.py): the implied density (mass / volume) lies in a range, and each principal
  moment is within a factor of the solid's at that mass (uniform density). W0710, W0711.

Findings are warnings (W0701, W0710, W0711; the test passes) unless the test is listed as
`- physical_validity: error`, which makes them failures.
"""

from __future__ import annotations

import numpy as np

from mpc.checks.protocol import Result, failed, first_of, passed, vector_text
from mpc.checks.registry import Context, register
from mpc.checks.shape_figures import figures
from mpc.checks.topology import MOVABLE
from mpc.core.span import Span
from mpc.ir.geometry import Box, Cylinder, Geometry, Sphere
from mpc.ir.inertia import principal
from mpc.ir.kinematics import pose_matrix
from mpc.ir.program import DENSITY, FACTOR, ModelTest
from mpc.ir.robot import Inertia, Robot
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
        bounds = figures(geometry).bounds
        if bounds is None:
            return None
        lo, hi = np.asarray(bounds[0]), np.asarray(bounds[1])
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


def findings(robot: Robot, distance: float, density: tuple[float, float] = DENSITY,
             factor: float = FACTOR) -> list[tuple[str, str, str]]:
    """(link, diagnostic code, problem) for every finding, in link order: W0701's, then the
    plausibility ones."""
    out = [(link, "W0701", problem) for link, problem in geometric_problems(robot, distance)]
    for name in sorted(robot.links):
        out += [(name, code, problem) for code, problem in plausibility(robot, name, density, factor)]
    return out


def plausibility(robot: Robot, name: str, density: tuple[float, float], factor: float
                 ) -> list[tuple[str, str]]:
    """(code, problem) for a link with mass whose collision shapes are a closed solid: the
    implied density outside `density` (W0710); a principal moment more than `factor` away from
    the solid's at the link's mass (W0711). Nothing for other links (unreadable or open meshes:
    the figures would be guesses)."""
    link = robot.links[name]
    inertial = link.inertial
    if inertial is None or inertial.mass <= 0 or not link.collisions:
        return []
    if len(link.collisions) == 1:  # the common case, from the cache (checks/shape_figures.py)
        one = figures(link.collisions[0].geometry)
        closed, volume, moments = one.closed, one.volume, np.asarray(one.moments)
    else:
        from mpc.ir.mesh_props import MeshError, solid
        from mpc.ir.solids import union

        try:
            whole = union([(solid(c.geometry), pose_matrix(c.origin)) for c in link.collisions])
        except MeshError:
            return []
        closed, volume = whole.closed, whole.props.mass
        moments = principal(whole.props) if volume > 0 else np.zeros(3)
    if not closed or volume <= 0:
        return []
    out = []
    rho = inertial.mass / volume
    if not density[0] <= rho <= density[1]:
        out.append(("W0710", f"implied density {rho:.4g} kg/m³ (mass {inertial.mass:.4g} kg in "
                             f"{volume:.4g} m³ of collision solid) lies outside "
                             f"{density[0]:g}–{density[1]:g} kg/m³"))
    declared = principal_moments(inertial.inertia)
    expected = moments * rho
    if declared[0] > 0 and expected[0] > 0:
        ratio = np.maximum(declared / expected, expected / declared)
        if float(np.max(ratio)) > factor:
            out.append(("W0711", f"principal moments {vector_text(declared)} kg·m² differ from the collision "
                                 f"solid's {vector_text(expected)} kg·m² at its mass by up to a factor of "
                                 f"{float(np.max(ratio)):.4g} (more than {factor:g})"))
    return out


def geometric_problems(robot: Robot, distance: float) -> list[tuple[str, str]]:
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
    found = findings(robot, ctx.tol.distance, test.density, test.inertia_factor)
    details = tuple(f"{link}: {problem}" for link, _, problem in found)
    figure = float(len(found))
    if not found:
        return passed(test.name, f"{len(robot.links)} links: masses, inertias and COMs are possible",
                      figure=0.0, unit="findings", tolerances=ctx.bound("distance", "m"))
    first = first_of([f"link '{link}' {problem}" for link, _, problem in found])
    if test.as_error:
        return failed(test.name, first, figure=figure, unit="findings", tolerances=ctx.bound("distance", "m"),
                      details=details)
    for link, code, problem in found:
        span = robot.links[link].span or Span.of_file(str(ctx.built.path))
        ctx.sink.warning(span, code, f"link '{link}' {problem}")
    return passed(test.name, f"{len(found)} warnings: {first}", figure=figure, unit="findings",
                  tolerances=ctx.bound("distance", "m"), details=details)

