"""`correct_inertials`: make non-physical inertials physical, leave physical ones alone.

A rigid body's inertial is physical when its mass is positive and its inertia about the
COM is positive-definite and satisfies the triangle inequality (each principal moment is
at most the sum of the other two). Phobos's `Robot.correct_inertials` sets every mass
below 1e-5 kg to 1e-5 and lifts every principal moment below 1e-5 kg·m² to 1e-5, which also
changes small physical bodies (a finger segment) and leaves a tensor that breaks the
triangle inequality broken; mpc changes only what is not physical:

- no `<inertial>`, or mass 0 with a zero tensor: a massless frame, left as it is
  (Phobos gives such links 1e-5 kg);
- a mass that is not positive, with a tensor: 1e-5 kg, Phobos's floor;
- a tensor that is not positive-definite or breaks the triangle inequality beyond
  rounding (1e-6 of its largest moment, what six written digits carry; the rule of
  `mpc test`'s physical_validity, checks/validity.py): the same amount d is added to each principal moment,
  I + d·1 (principal axes kept), the least d that makes it physical plus a margin of
  1e-3 of its largest moment (1e-5 kg·m² for a zero tensor, Phobos's floor).

SDFormat reads an inertial by gz-math's `MassMatrix3::IsValid` (`sdformat_problems`): no
rounding is forgiven there beyond ten machine epsilons of half the trace, so for an SDF or
MJCF export `correct_inertials(robot, exact=True)` lifts a tensor broken by any amount.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mpc.ir.robot import Inertia, Inertial, Robot

FLOOR = 1e-5  # Phobos's limit: kg for a mass, kg·m² for a zero tensor
MARGIN = 1e-3  # of the largest principal moment, beyond the least correction
ROUNDING = 1e-6  # of the largest moment: a triangle inequality broken by less is rounding


def _matrix(i: Inertia) -> np.ndarray:
    return np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])


def principal_moments(i: Inertia) -> np.ndarray | None:
    """The principal moments of `i`, ascending; None when they are no numbers (a tensor
    holding a number that is not finite, or so large that the eigenvalues overflow or do not
    converge)."""
    try:
        moments = np.linalg.eigvalsh(_matrix(i))
    except np.linalg.LinAlgError:
        return None
    return moments if np.isfinite(moments).all() else None


TOO_LARGE = "its inertia is too large for its principal moments to be numbers (they overflow)"


def lift(i: Inertia, exact: bool = False) -> float:
    """The amount to add to each principal moment of `i` (0 when it is physical, or when its
    moments are no numbers: nothing makes it physical, and the exports refuse it); `exact`:
    forgive no rounding beyond SDFormat's (`sdformat_problems`)."""
    moments = principal_moments(i)  # ascending: only a + b >= c can fail
    if moments is None:
        return 0.0
    a, b, c = (float(m) for m in moments)
    broken = c - a - b
    if a > 0 and broken <= (_gz_epsilon(moments) if exact else ROUNDING * max(abs(a), abs(c))):
        return 0.0
    largest = c
    return max(0.0, -a, broken) + (MARGIN * largest if largest > 0 else FLOOR)


def corrected(inertial: Inertial, exact: bool = False) -> Inertial | None:
    """The physical version of `inertial`, or None when it is physical (or a massless frame)."""
    i = inertial.inertia
    zero_tensor = not any((i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz))
    if inertial.mass == 0 and zero_tensor:
        return None
    mass = inertial.mass if inertial.mass > 0 else FLOOR
    d = lift(i, exact)
    if d == 0 and mass == inertial.mass:
        return None
    return replace(inertial, mass=mass, inertia=replace(i, ixx=i.ixx + d, iyy=i.iyy + d, izz=i.izz + d))


def correct_inertials(robot: Robot, exact: bool = False) -> tuple[Robot, tuple[str, ...]]:
    """`robot` with every non-physical inertial made physical, and the links that changed;
    `exact`: by SDFormat's rule, which forgives no rounding."""
    links, changed = dict(robot.links), []
    for name, link in robot.links.items():
        new = corrected(link.inertial, exact) if link.inertial is not None else None
        if new is not None:
            links[name] = replace(link, inertial=new)
            changed.append(name)
    return (replace(robot, links=links) if changed else robot), tuple(changed)


def _gz_epsilon(moments: np.ndarray) -> float:
    """gz-math's tolerance for an inertia of these moments: 10 machine epsilons of the
    largest moment a tensor of this trace can have (half the trace)."""
    return 10 * float(np.finfo(float).eps) * 0.5 * abs(float(np.sum(moments)))


def sdformat_problems(inertial: Inertial) -> list[str]:
    """Why SDFormat refuses `inertial` ("A link named … has invalid inertia", gz-math's
    `MassMatrix3::IsValid`): a negative mass, a tensor not positive semi-definite, or
    principal moments violating A + B ≥ C, each beyond `_gz_epsilon`. A zero mass and
    tensor is valid (a massless frame). Empty when SDFormat accepts it."""
    moments = principal_moments(inertial.inertia)
    if moments is None:
        return [TOO_LARGE]
    a, b, c = (float(m) for m in moments)
    epsilon = _gz_epsilon(moments)
    problems = []
    if inertial.mass < 0:
        problems.append(f"its mass {_g(inertial.mass)} is negative")
    if a < -epsilon:
        problems.append(f"its inertia is not positive semi-definite (principal moment {_g(a)})")
    elif a + b + epsilon < c:
        problems.append(f"its principal moments violate A + B ≥ C ({_g(a)} + {_g(b)} "
                        f"< {_g(c)})")
    return problems


def _g(x: float) -> str:
    return f"{x:.6g}"
