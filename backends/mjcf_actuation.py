"""The MJCF export's actuators: which joints MuJoCo drives, how, with which gains and ranges.

A motor of the definition (or SMURF) becomes the actuator its `type` names (Phobos's control
type; `position` when not set, as in Phobos): position → `<position>` (a PD servo), velocity →
`<velocity>`, force/effort/torque → `<motor>` (a torque source). The export option `actuators`
says what the joints without a motor get: `motors` (the default) nothing, `position`,
`velocity` or `motor` that actuator on every joint of one degree of freedom that no motor
drives and that follows no other (a mimic follower is driven by its equality), `none` no
actuator at all, not even the motors'.

Gains and ranges, in the joint's units (rad or m):
- position: kp = the motor's `p`; kv = its `d`, else `dampratio="1"` (MuJoCo computes the
  critically damping kv from the joint's reflected inertia). Without `p`, kp reaches the
  joint's effort limit 0.1 rad (m) from the target: kp = effort / 0.1. ctrlrange = the joint's
  position range (none on a continuous joint).
- velocity: kv = `p`, else effort / 0.1 (the effort limit at 0.1 rad/s of error); ctrlrange =
  ± the joint's velocity limit.
- motor: ctrlrange = ± the effort limit (the control is the torque or force).
Every actuator's forcerange is ± the joint's effort limit. Without an effort limit and a `p`, a
gain is left to MuJoCo's default (1).
"""

from __future__ import annotations

from collections.abc import Iterator

from mpc.backends import holds
from mpc.core.record import record
from mpc.ir.robot import Joint, Robot
from mpc.ir.tree import depth_first

__all__ = ["ACTUATOR_MODES", "CANNOT_HOLD", "Actuator", "actuators", "kind_of"]

ACTUATOR_MODES = ("motors", "position", "velocity", "motor", "none")
ONE_DOF = ("revolute", "continuous", "prismatic")
FULL_EFFORT_AT = 0.1  # rad (m), rad/s (m/s): the error at which a default gain reaches the effort limit
# Phobos's and MARS's names of a motor's control type → MuJoCo's actuator.
KINDS = {"position": "position", "pid": "position", "servo": "position",
         "velocity": "velocity", "dc": "velocity",
         "force": "motor", "effort": "motor", "torque": "motor", "motor": "motor", "directeffort": "motor"}
# The settings an actuator of each kind uses; maxEffort and maxSpeed are the joint's limits.
USED = {"position": {"type", "p", "d", "maxEffort", "maxSpeed"},
        "velocity": {"type", "p", "maxEffort", "maxSpeed"}, "motor": {"type", "maxEffort", "maxSpeed"}}


@record(slots=True)
class Actuator:
    """One actuator element: tag (position, velocity, motor), name, joint and its attributes
    (name → number or text; None: left out)."""

    tag: str
    name: str
    joint: str
    attrs: tuple[tuple[str, float | tuple[float, ...] | str | None], ...]


def kind_of(motor_type: object) -> str | None:
    """The actuator tag of a motor's `type` (position when not set), or None for a type MuJoCo
    has no actuator for."""
    if motor_type is None:
        return "position"
    return KINDS.get(str(motor_type).lower())


def _number(value: object) -> float | None:
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else None


def _driven(robot: Robot, joint: Joint | None) -> bool:
    return joint is not None and joint.type in ONE_DOF


def _follower(robot: Robot, joint: Joint) -> bool:
    m = joint.mimic
    return m is not None and _driven(robot, robot.joints.get(m.joint))


def _actuator(tag: str, name: str, joint: Joint, settings: dict[str, object]) -> Actuator:
    lim = joint.limit
    effort = abs(lim.effort) if lim is not None and lim.effort else None
    p, d = _number(settings.get("p")), _number(settings.get("d"))
    default_gain = effort / FULL_EFFORT_AT if effort else None
    force = (-effort, effort) if effort else None
    attrs: list[tuple[str, float | tuple[float, ...] | str | None]] = []
    if tag == "position":
        rng = None  # the joint's range as the MJCF writes it (a missing bound is 0, as in URDF)
        if joint.type != "continuous" and lim is not None and (lim.lower, lim.upper) != (None, None):
            lo, hi = lim.lower or 0.0, lim.upper or 0.0
            rng = (lo, hi) if lo < hi else None
        attrs = [("kp", p if p is not None else default_gain),
                 ("kv", d if d else None), ("dampratio", None if d else "1"), ("ctrlrange", rng)]
    elif tag == "velocity":
        speed = abs(lim.velocity) if lim is not None and lim.velocity else None
        attrs = [("kv", p if p is not None else default_gain),
                 ("ctrlrange", (-speed, speed) if speed else None)]
    else:
        attrs = [("ctrlrange", force)]
    return Actuator(tag, name, joint.name, (*attrs, ("forcerange", force)))


def actuators(robot: Robot, mode: str = "motors") -> list[Actuator]:
    """The actuators of the MJCF, in the joints' depth-first order (the motors of one joint by
    name, then the one `mode` adds): see the module."""
    if mode == "none":
        return []
    motors: dict[str, list[tuple[str, dict[str, object]]]] = {}
    for name in sorted(robot.motors):
        m = robot.motors[name]
        motors.setdefault(m.joint, []).append((name, dict(m.settings)))
    names = set(robot.motors)
    out = []
    for joint, _ in depth_first(robot):
        if joint is None or not _driven(robot, joint):
            continue
        for name, settings in motors.get(joint.name, []):
            tag = kind_of(settings.get("type"))
            if tag is not None:
                out.append(_actuator(tag, name, joint, settings))
        if mode != "motors" and joint.name not in motors and not _follower(robot, joint):
            name, n = joint.name, 1
            while name in names:
                name, n = f"{joint.name}_{n}", n + 1
            names.add(name)
            out.append(_actuator(mode, name, joint, {}))
    return out


# -- what the actuators leave out (W0500, read by backends/mjcf.py CANNOT_HOLD) ------------

def _unknown_types(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for name in sorted(robot.motors):
        m = robot.motors[name]
        if options.get("actuators", "motors") != "none" and kind_of(m.settings.get("type")) is None:
            yield holds.Named(f"motor '{name}' of type '{m.settings.get('type')}' (MuJoCo has no actuator "
                              "for it; position, velocity and force/effort/torque it has)"), 1


def _unused_settings(robot: Robot, options: holds.Options) -> int:
    """The settings of the written motors that their actuators do not use (a motor left out
    as a whole is named or counted as one, not by its settings)."""
    n = 0
    for m in robot.motors.values():
        tag = kind_of(m.settings.get("type"))
        if options.get("actuators", "motors") == "none" or tag is None \
                or not _driven(robot, robot.joints.get(m.joint)):
            continue
        n += sum(k not in USED[tag] and not (k in ("i", "d") and _number(v) == 0)
                 for k, v in m.settings.items())
    return n


def _undriven(robot: Robot, options: holds.Options) -> int:
    return 0 if options.get("actuators", "motors") == "none" else sum(
        not _driven(robot, robot.joints.get(m.joint)) for m in robot.motors.values())


_C = holds.Counted
CANNOT_HOLD: tuple[holds.Tally, ...] = (
    holds.count(_C("motor setting", "motor settings"), _unused_settings),
    holds.count(_C("motor of a joint without one degree of freedom", "motors of joints without one degree "
                   "of freedom"), _undriven),
    _unknown_types,
    holds.count(_C("motor (actuators: none)", "motors (actuators: none)"),
                lambda r, o: len(r.motors) if o.get("actuators", "motors") == "none" else 0),
)
