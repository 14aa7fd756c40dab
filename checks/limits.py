"""joint_limits: every joint's position limits, velocity and effort against the compare
model's, and mirrored joints against each other (no dynamics library).

A joint's figures are its `<limit>`'s lower and upper (revolute and prismatic joints: a
continuous joint has no position limits), velocity and effort; a figure that one side has
and the other lacks is a difference. Mirrored joints (`mirrored: [left, right]`: the name
with `left` replaced by `right`) have the same velocity and effort, and the same range, as
it is or negated (mirroring a joint may turn its axis: [-1, 2] and [-2, 1] are the same range).
"""

from __future__ import annotations

from mpc.checks.protocol import Result, Tolerance, counted, failed, first_of, passed
from mpc.checks.registry import Context, register
from mpc.ir.program import ModelTest
from mpc.ir.robot import Joint, Robot

_MOVABLE = ("revolute", "continuous", "prismatic")
_FIGURES = ("lower", "upper", "velocity", "effort")


def _bounds(ctx: Context, test: ModelTest) -> dict[str, Tolerance]:
    """The bound of each figure: the test's own (`position`, `velocity`, `effort`) or the
    tolerance it defaults to (`rad` and `distance` for positions, `default` for the others)."""
    own = test.limit_tolerances or {}

    def bound(key: str, default: str, unit: str) -> Tolerance:
        if key in own:
            return Tolerance(key, own[key], unit)
        return Tolerance(default, getattr(ctx.tol, default), unit)

    return {"rad": bound("position", "rad", "rad"), "m": bound("position", "distance", "m"),
            "velocity": bound("velocity", "default", "rad/s or m/s"),
            "effort": bound("effort", "default", "N·m or N")}


def _figures(joint: Joint) -> dict[str, float | None]:
    """lower, upper, velocity, effort as the joint states them (None: not stated)."""
    limit = joint.limit
    if limit is None:
        return dict.fromkeys(_FIGURES)
    positions = joint.type in ("revolute", "prismatic")
    return {"lower": limit.lower if positions else None, "upper": limit.upper if positions else None,
            "velocity": limit.velocity, "effort": limit.effort}


def _bound_of(figure: str, joint: Joint, bounds: dict[str, Tolerance]) -> Tolerance:
    if figure in ("lower", "upper"):
        return bounds["m" if joint.type == "prismatic" else "rad"]
    return bounds[figure]


def _differences(old: Joint, new: Joint, bounds: dict[str, Tolerance]) -> list[str]:
    """'upper 2.5 → 1 (Δ -1.5 rad)' for each figure of `new` that left `old`'s bound."""
    before, after = _figures(old), _figures(new)
    out = []
    for figure in _FIGURES:
        a, b = before[figure], after[figure]
        if a is None and b is None:
            continue
        bound = _bound_of(figure, new, bounds)
        unit = bound.unit.split(" or ")[0 if new.type != "prismatic" else -1]
        if a is None or b is None:
            out.append(f"{figure} {_text(a)} → {_text(b)}")
        elif abs(b - a) > bound.value:
            out.append(f"{figure} {a:g} → {b:g} (Δ {b - a:+.4g} {unit})")
    return out


def _text(value: float | None) -> str:
    return "none" if value is None else f"{value:g}"


def _movable(robot: Robot) -> dict[str, Joint]:
    return {n: j for n, j in robot.joints.items() if j.type in _MOVABLE}


def release_problems(old: Robot, new: Robot, bounds: dict[str, Tolerance]) -> list[str]:
    """A line for each joint of both models whose limits differ beyond the bounds."""
    before, after = _movable(old), _movable(new)
    out = []
    for name in sorted(set(before) & set(after)):
        changes = _differences(before[name], after[name], bounds)
        if changes:
            out.append(f"joint '{name}': " + ", ".join(changes) + " (the release → now)")
    return out


def mirror_problems(robot: Robot, sides: tuple[str, str], bounds: dict[str, Tolerance]
                    ) -> tuple[int, list[str]]:
    """The number of mirrored pairs, and a line for each pair whose limits differ: velocity
    or effort beyond its bound, or a range that is neither the other's nor its negation."""
    left, right = sides
    joints = _movable(robot)
    pairs = [(n, n.replace(left, right)) for n in sorted(joints)
             if left in n and n.replace(left, right) in joints]
    out = []
    for a, b in pairs:
        l_fig, r_fig = _figures(joints[a]), _figures(joints[b])
        changes = _differences(joints[a], joints[b], bounds)
        position = [c for c in changes if c.startswith(("lower", "upper"))]
        if position:  # the same range negated is a mirror image too
            lo, up = l_fig["lower"], l_fig["upper"]
            negated = {"lower": None if up is None else -up, "upper": None if lo is None else -lo}
            bound = _bound_of("lower", joints[b], bounds).value
            if all(negated[k] is not None and r_fig[k] is not None and abs(negated[k] - r_fig[k]) <= bound  # type: ignore[operator]
                   for k in ("lower", "upper")):
                changes = [c for c in changes if c not in position]
        if changes:
            out.append(f"joints '{a}' and '{b}': " + ", ".join(changes) + f" ('{a}' → '{b}')")
    return len(pairs), out


@register("joint_limits")
def joint_limits(ctx: Context, test: ModelTest) -> Result:
    """The limits of every joint against the compare model's; with `mirrored`, mirrored joints'
    against each other. Without a compare model only the mirrored joints are compared."""
    missing = ctx.need_both(test.name)
    if missing is not None and (missing.failed or test.mirrored is None):
        return missing
    bounds = _bounds(ctx, test)
    tolerances = tuple(dict.fromkeys(bounds.values()))
    problems = [] if missing is not None else release_problems(ctx.compare.robot, ctx.built.robot, bounds)
    pairs = 0
    if test.mirrored is not None:
        pairs, mirrored = mirror_problems(ctx.built.robot, test.mirrored, bounds)
        if pairs == 0:
            problems.append(f"no joint has a mirror image: no name holds '{test.mirrored[0]}' with a "
                            f"joint of the name with '{test.mirrored[1]}' for it")
        problems += mirrored
    joints = len(_movable(ctx.built.robot))
    what = counted(joints, "movable joint")
    what += "" if missing is None else " (no compare_model: mirrored joints only)"
    what += f", {counted(pairs, 'mirrored pair')}" if test.mirrored is not None else ""
    if problems:
        return failed(test.name, first_of(problems), figure=float(len(problems)), unit="joints",
                      tolerances=tolerances, details=tuple(problems))
    return passed(test.name, f"the limits of {what} agree", figure=0.0, unit="joints", tolerances=tolerances)
