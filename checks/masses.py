"""Tests of masses and link placements read from the model files (no dynamics library):
compare_link_masses, compare_link_transformations, total_mass, symmetry_check_masses."""

from __future__ import annotations

import numpy as np

from mpc.checks.protocol import Result, Tolerance, failed, skipped, verdict
from mpc.checks.registry import Context, register
from mpc.ir.kinematics import links_in_root
from mpc.ir.program import ModelTest
from mpc.ir.robot import Robot
from mpc.ir.tree import joints_up


def link_mass(robot: Robot, link: str) -> float:
    """The link's mass; 0 for a link without inertial and for a link the robot lacks."""
    found = robot.links.get(link)
    inertial = found.inertial if found is not None else None
    return inertial.mass if inertial is not None else 0.0


def total_mass_of(robot: Robot) -> float:
    return sum(link_mass(robot, n) for n in robot.links)


def rotation_angle(R: np.ndarray) -> float:
    """The geodesic angle of a rotation matrix (radians, 0…π)."""
    return float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


@register("compare_link_masses", needs="both")
def compare_link_masses(ctx: Context, test: ModelTest) -> Result:
    """Every link's mass against the compare model's, |Δm| ≤ `mass`. A link in only one of
    the models counts with its whole mass (a mass that appeared or disappeared)."""
    new, old = ctx.built.robot, ctx.compare.robot
    diffs = {n: link_mass(new, n) - link_mass(old, n) for n in set(new.links) | set(old.links)}
    return differences_verdict(test.name, diffs, *ctx.bound("mass", "kg"), "link mass", "link masses")


def differences_verdict(name: str, diffs: dict[str, float], bound: Tolerance, what: str,
                        whats: str = "") -> Result:
    """A verdict over named differences (Δ per link or link pair): every |Δ| ≤ the bound;
    the figure is the worst |Δ|."""
    tol, unit = bound.value, bound.unit
    order = sorted(diffs, key=lambda n: (-abs(diffs[n]), n))
    worst = abs(diffs[order[0]]) if order else 0.0
    bad = [n for n in order if abs(diffs[n]) > tol]
    details = tuple(f"{n}: Δ = {diffs[n]:+.6g} {unit}" for n in order if abs(diffs[n]) > 0)
    whats = whats or what + "s"
    differ = f"{what} differs" if len(bad) == 1 else f"{whats} differ"
    reason = (f"{len(bad)} {differ} by more than {tol:g} {unit}, most "
              f"'{bad[0]}' by {diffs[bad[0]]:+.6g} {unit}") if bad else \
        f"{len(diffs)} {whats} within {tol:g} {unit}"
    return verdict(name, not bad, reason, figure=worst, unit=unit, tolerances=(bound,), details=details)


@register("compare_link_transformations", needs="both")
def compare_link_transformations(ctx: Context, test: ModelTest) -> Result:
    """Every link's pose in the root at q = 0 against the compare model's: the position error
    ≤ `distance` and the geodesic rotation angle of X_old⁻¹·X_new ≤ `rad`. Links in only
    one model are left to topological_self_consistency."""
    new, old = ctx.built.robot, ctx.compare.robot
    rows = []
    X_R_new, X_R_old = links_in_root(new), links_in_root(old)
    for link in sorted(set(new.links) & set(old.links)):
        X_new, X_old = X_R_new[link], X_R_old[link]
        rows.append((link, float(np.linalg.norm(X_new[:3, 3] - X_old[:3, 3])),
                     rotation_angle(X_old[:3, :3].T @ X_new[:3, :3])))
    return pose_verdict(test.name, rows, ctx.tol.distance, ctx.tol.rad)


def pose_verdict(name: str, rows: list[tuple[str, float, float]], distance: float, rad: float) -> Result:
    """A verdict over (link, position error, angle) rows: the figure is the worst position error."""
    bad = [r for r in rows if r[1] > distance or r[2] > rad]
    rows = sorted(rows, key=lambda r: (-r[1], -r[2], r[0]))
    details = tuple(f"{n}: position {d:.6g} m, rotation {a:.6g} rad" for n, d, a in rows if d > 0 or a > 0)
    worst = rows[0][1] if rows else 0.0
    worst_angle = max((r[2] for r in rows), default=0.0)
    if bad:
        n, d, a = max(bad, key=lambda r: r[1] / (distance or 1.0) + r[2] / (rad or 1.0))
        reason = (f"{len(bad)} link{'s' * (len(bad) != 1)} moved beyond {distance:g} m or {rad:g} rad, "
                  f"most '{n}' by {d:.6g} m and {a:.6g} rad")
    else:
        reason = (f"{len(rows)} links within {distance:g} m and {rad:g} rad "
                  f"(worst rotation {worst_angle:.3g} rad)")
    bounds = (Tolerance("distance", distance, "m"), Tolerance("rad", rad, "rad"))
    return verdict(name, not bad, reason, figure=worst, unit="m", tolerances=bounds, details=details)


@register("total_mass")
def total_mass(ctx: Context, test: ModelTest) -> Result:
    """The model's total mass against the expected one (the argument, else `expected_mass`
    from test_data_file): |m − expected| ≤ `mass`."""
    expected = test.value if test.value is not None else ctx.plan.expected_mass
    if expected is None:
        return skipped(test.name, "no expected mass: give one (`- total_mass: 12.5`) or a test_data_file "
                       "with test_data: {expected_mass: …}")
    mass = total_mass_of(ctx.built.robot)
    diff = mass - expected
    old = f"; the compare model has {total_mass_of(ctx.old.robot):.6g} kg" if ctx.old else ""
    return verdict(test.name, abs(diff) <= ctx.tol.mass,
                   f"total mass {mass:.6g} kg, expected {expected:.6g} kg{old}", figure=abs(diff), unit="kg",
                   tolerances=ctx.bound("mass", "kg"))


def chain(robot: Robot, link: str) -> list[str]:
    """The links from the root down to `link` (fixed joints included)."""
    return [robot.root, *(j.child for j in reversed(joints_up(robot, link)))]


@register("symmetry_check_masses")
def symmetry_check_masses(ctx: Context, test: ModelTest) -> Result:
    """The links on the way from the root to the left and to the right link, pairwise from
    where the two ways part: equal in number and |m_L − m_R| ≤ `mass`."""
    robot = ctx.built.robot
    left, right = test.links
    for link in test.links:
        if link not in robot.links:
            return failed(test.name, f"link '{link}' is not in the model")
    a, b = chain(robot, left), chain(robot, right)
    shared = 0
    while shared < min(len(a), len(b)) and a[shared] == b[shared]:
        shared += 1
    a, b = a[shared:], b[shared:]
    if len(a) != len(b):
        return failed(test.name, f"the way to '{left}' has {len(a)} links after the branch, the way to "
                      f"'{right}' {len(b)}", details=(" → ".join(a), " → ".join(b)))
    diffs = {f"{x} / {y}": link_mass(robot, x) - link_mass(robot, y) for x, y in zip(a, b, strict=True)}
    return differences_verdict(test.name, diffs, *ctx.bound("mass", "kg"), "link pair")
