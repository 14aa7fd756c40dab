"""The dynamics checks (Phobos's `hyrodynChecks`), done with Pinocchio: load_in_hyrodyn (the
model loads in the dynamics library), compare_masses, compare_com, compare_torques,
compare_link_positions, symmetry_check, symmetry_check_torques, and move_hyrodyn_model,
which sets the configuration of the checks after it.

Loop closures (cut joints) are constraints (checks/dynamics_model.py); a configuration
moves the actuated joints and closes the loops with the others.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mpc.checks.dynamics_model import DynamicsError
from mpc.checks.masses import pose_verdict, rotation_angle
from mpc.checks.models import Model
from mpc.checks.protocol import Result, failed, passed, skipped, vector_text, verdict
from mpc.checks.registry import Context, register
from mpc.ir.program import ModelTest
from mpc.ir.tree import joints_up


class _CheckFailed(Exception):
    """Raised inside a check to end it with `result` (a failed one, with the reason)."""

    def __init__(self, result: Result) -> None:
        self.result = result


def _dynamics_of(model: Model, name: str, which: str) -> Any:
    """The model's Pinocchio model (dynamics_model.Dynamics); `which` names it in the reason."""
    try:
        return model.dynamics()
    except DynamicsError as e:
        raise _CheckFailed(failed(name, f"the {which} does not load in Pinocchio: {e}")) from None


def _state(ctx: Context, model: Model, name: str, which: str) -> tuple[Any, np.ndarray]:
    """The model's dynamics and its q at the current configuration."""
    dyn = _dynamics_of(model, name, which)
    # The compare model moves the joints the compiled model drives (its file may not say).
    actuated = None
    if model is not ctx.new and ctx.new is not None:
        actuated = _dynamics_of(ctx.new, name, "compiled model").actuated
    try:
        return dyn, dyn.configuration(ctx.configuration, actuated)
    except DynamicsError as e:
        raise _CheckFailed(failed(name, f"the {which}: {e}")) from None


def _where(ctx: Context) -> str:
    if not ctx.configuration:
        return "at q = 0"
    values = sorted(set(ctx.configuration.values()))
    if len(ctx.configuration) > 3 and len(values) == 1:
        return f"at {values[0]:g} for every joint"
    if len(ctx.configuration) <= 3:
        return "at " + ", ".join(f"{k} = {v:g}" for k, v in ctx.configuration.items())
    return "at the configuration set"


def _reasons_for_failures(fn: Any) -> Any:
    """A check whose model is missing, or whose mechanism Pinocchio cannot solve (a loop
    that does not close, actuated joints that cannot hold it), fails with that reason."""
    def run(ctx: Context, test: ModelTest) -> Result:
        try:
            return fn(ctx, test)
        except _CheckFailed as m:
            return m.result
        except DynamicsError as e:
            return failed(test.name, str(e))
    run.__doc__ = fn.__doc__
    return run


def _both_states(ctx: Context, test: ModelTest) -> tuple[Any, np.ndarray, Any, np.ndarray]:
    a, qa = _state(ctx, ctx.built, test.name, "compiled model")
    b, qb = _state(ctx, ctx.compare, test.name, "compare model")
    return a, qa, b, qb


@register("load_in_hyrodyn", dynamics=True)
@_reasons_for_failures
def load_in_hyrodyn(ctx: Context, test: ModelTest) -> Result:
    """The compiled model (and the compare model, when there is one) loads in the dynamics
    library, Pinocchio, with its loop closures."""
    dyn, _ = _state(ctx, ctx.built, test.name, "compiled model")
    if ctx.old is not None:
        _state(ctx, ctx.old, test.name, "compare model")
    n = len(dyn.constraints)
    loops = f", {n} loop closure{'s' * (n != 1)}" if n else ""
    return passed(test.name, f"Pinocchio: {dyn.model.njoints - 1} joints, {dyn.model.nq} coordinates{loops}",
                  figure=float(dyn.model.nv), unit="DoF")


@register("compare_masses", dynamics=True, needs="both")
@_reasons_for_failures
def compare_masses(ctx: Context, test: ModelTest) -> Result:
    """|total mass − the compare model's| ≤ `mass` (both ways: a heavier model fails too)."""
    a, _, b, _ = _both_states(ctx, test)
    diff = a.total_mass() - b.total_mass()
    return verdict(test.name, abs(diff) <= ctx.tol.mass,
                   f"total mass {a.total_mass():.6g} kg, the compare model {b.total_mass():.6g} kg",
                   figure=abs(diff), unit="kg", tolerances=ctx.bound("mass", "kg"))


@register("compare_com", dynamics=True, needs="both")
@_reasons_for_failures
def compare_com(ctx: Context, test: ModelTest) -> Result:
    """‖COM − the compare model's COM‖ ≤ `distance`, in the root frame, at the configuration."""
    a, qa, b, qb = _both_states(ctx, test)
    ca, cb = a.com(qa), b.com(qb)
    dist = float(np.linalg.norm(ca - cb))
    return verdict(test.name, dist <= ctx.tol.distance,
                   f"COM {vector_text(ca)} m, the compare model {vector_text(cb)} m {_where(ctx)}",
                   figure=dist, unit="m", tolerances=ctx.bound("distance", "m"))


@register("compare_torques", dynamics=True, needs="both")
@_reasons_for_failures
def compare_torques(ctx: Context, test: ModelTest) -> Result:
    """The gravity torques of the compiled model's actuated joints (or the joints given) in
    both models, |Δτ| ≤ `default` (N·m or N), at the configuration; loops closed. The compare
    model is asked for the same joints' torques, so that a compare file that does not say
    which joints are driven (URDF, SDF) is measured like the compiled model."""
    a, qa, b, qb = _both_states(ctx, test)
    ta = a.gravity_torques(qa, test.links or None)
    tb = b.gravity_torques(qb, tuple(ta))
    joints = list(test.links) or list(ta)
    unknown = [j for j in joints if j not in ta or j not in tb]
    if unknown:
        return failed(test.name, f"joint '{unknown[0]}' is not an actuated joint of both models")
    if not joints:  # no joint to hold: nothing was measured, so nothing passed
        return skipped(test.name, "the compiled model has no actuated joint")
    diffs = {j: ta[j] - tb[j] for j in joints}
    worst = max(joints, key=lambda j: (abs(diffs[j]), j))
    details = tuple(f"{j}: τ = {ta[j]:+.6g}, compare {tb[j]:+.6g}, Δ = {diffs[j]:+.3g}"
                    for j in sorted(joints, key=lambda j: -abs(diffs[j])))
    n = len(a.constraints)
    loops = f" with {n} loop closure{'s' * (n != 1)}" if n else ""
    return verdict(test.name, abs(diffs[worst]) <= ctx.tol.default,
                   f"{len(joints)} joint torques{loops} {_where(ctx)}, worst '{worst}' "
                   f"Δ = {diffs[worst]:+.3g}",
                   figure=abs(diffs[worst]), unit="N·m", tolerances=ctx.bound("default", "N·m"),
                   details=details)


@register("compare_link_positions", dynamics=True, needs="both")
@_reasons_for_failures
def compare_link_positions(ctx: Context, test: ModelTest) -> Result:
    """The given links' (every shared link's, when none is given) positions ≤ `distance` and
    orientations ≤ `rad` against the compare model, at the configuration."""
    a, qa, b, qb = _both_states(ctx, test)
    pa, pb = a.link_placements(qa), b.link_placements(qb)
    links = list(test.links) or sorted(set(pa) & set(pb))
    unknown = [n for n in links if n not in pa or n not in pb]
    if unknown:
        return failed(test.name, f"link '{unknown[0]}' is not in both models")
    rows = [(n, float(np.linalg.norm(pa[n][:3, 3] - pb[n][:3, 3])),
             rotation_angle(pb[n][:3, :3].T @ pa[n][:3, :3])) for n in links]
    return pose_verdict(test.name, rows, ctx.tol.distance, ctx.tol.rad)


def _mirror(p: np.ndarray, plane: tuple[float, float, float]) -> np.ndarray:
    n = np.asarray(plane, dtype=float)
    n = n / np.linalg.norm(n)
    return p - 2.0 * float(p @ n) * n


@register("symmetry_check", dynamics=True)
@_reasons_for_failures
def symmetry_check(ctx: Context, test: ModelTest) -> Result:
    """The right link's position is the left one's mirrored in the plane through the root's
    origin with normal `plane` (default y: the xz-plane), within `distance`."""
    dyn, q = _state(ctx, ctx.built, test.name, "compiled model")
    placements = dyn.link_placements(q)
    left, right = test.links
    for link in test.links:
        if link not in placements:
            return failed(test.name, f"link '{link}' is not in the model")
    pl, pr = placements[left][:3, 3], placements[right][:3, 3]
    mirrored = _mirror(pl, test.plane)
    dist = float(np.linalg.norm(pr - mirrored))
    return verdict(test.name, dist <= ctx.tol.distance,
                   f"'{right}' at {vector_text(pr)} m, '{left}' mirrored at {vector_text(mirrored)} m "
                   f"(plane normal {vector_text(np.asarray(test.plane))})", figure=dist, unit="m",
                   tolerances=ctx.bound("distance", "m"))


@register("symmetry_check_torques", dynamics=True)
@_reasons_for_failures
def symmetry_check_torques(ctx: Context, test: ModelTest) -> Result:
    """The actuated joints on the way to the left and the right link, pairwise from where the
    two ways part: equal magnitudes of gravity torque, ||τ_L| − |τ_R|| ≤ `default`. Magnitudes,
    because a mirrored joint axis may flip the sign."""
    robot = ctx.built.robot
    dyn, q = _state(ctx, ctx.built, test.name, "compiled model")
    for link in test.links:
        if link not in robot.links:
            return failed(test.name, f"link '{link}' is not in the model")
    tau = dyn.gravity_torques(q)
    ways = [[j.name for j in reversed(joints_up(robot, link)) if j.name in tau] for link in test.links]
    shared = 0
    while shared < min(map(len, ways)) and ways[0][shared] == ways[1][shared]:
        shared += 1
    left, right = ways[0][shared:], ways[1][shared:]
    if len(left) != len(right):
        return failed(test.name, f"{len(left)} actuated joints lead to '{test.links[0]}', {len(right)} to "
                      f"'{test.links[1]}'", details=(" → ".join(left), " → ".join(right)))
    diffs = {f"{a} / {b}": abs(tau[a]) - abs(tau[b]) for a, b in zip(left, right, strict=True)}
    worst = max(diffs, key=lambda k: abs(diffs[k]), default="")
    figure = abs(diffs[worst]) if worst else 0.0
    return verdict(test.name, figure <= ctx.tol.default,
                   f"{len(diffs)} joint pairs {_where(ctx)}" + (f", worst {worst}" if worst else ""),
                   figure=figure, unit="N·m", tolerances=ctx.bound("default", "N·m"),
                   details=tuple(f"{k}: {v:+.3g}" for k, v in diffs.items()))


@register("move_hyrodyn_model", dynamics=True)
@_reasons_for_failures
def move_hyrodyn_model(ctx: Context, test: ModelTest) -> Result:
    """Set the configuration of the dynamics checks that follow, for both models: one value
    for every joint, one per joint (in the compiled model's joint order), or by joint name.
    A configuration that cannot be set (an unknown joint, loops that do not close there)
    fails this check and leaves the configuration as it was."""
    dyn = _dynamics_of(ctx.built, test.name, "compiled model")
    joints = dyn.joint_names()
    if test.joint_angles is not None:
        unknown = sorted(set(test.joint_angles) - set(joints))
        if unknown:
            return failed(test.name, f"joint '{unknown[0]}' is not a movable joint of the model")
        values = dict(test.joint_angles)
    elif test.angles:
        if len(test.angles) != len(joints):
            return failed(test.name, f"{len(test.angles)} values for {len(joints)} movable joints "
                          f"({', '.join(joints)})")
        values = dict(zip(joints, test.angles, strict=True))
    else:
        assert test.angle is not None
        values = dict.fromkeys(dyn.actuated if dyn.constraints else joints, test.angle)
    previous, ctx.configuration = ctx.configuration, values
    try:
        _state(ctx, ctx.built, test.name, "compiled model")  # the loops must close there
    except _CheckFailed:
        ctx.configuration = previous  # the checks after it keep the configuration they had
        raise
    return passed(test.name, f"the checks after this one run {_where(ctx)}",
                  details=tuple(f"{k} = {v:g}" for k, v in values.items()))

