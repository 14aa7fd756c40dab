"""A robot value → a Pinocchio model with its loop closures: mass, COM, link placements and
the gravity torques of the actuated joints, at a configuration that closes the loops.

Fixed base. Pinocchio puts the root link's inertia into `inertias[0]` and leaves it out of
`computeTotalMass`, so mass and COM are summed here over every body, the root included.
A cut joint becomes a `pin.RigidConstraintModel` between the parent joints of its two links:
6D for a fixed closure, a 3D point constraint at the joint's origin for ball, revolute,
continuous and universal ones (a revolute closure's two rotational constraints are left
out: in a planar loop they are redundant, in a spatial one the mechanism is then checked
as if the closure were a ball joint).

A mimic joint (URDF `<mimic>`) follows its joint, q_k = multiplier · q_j + offset: it is not
actuated and not set by a configuration; the coupling is one more constraint row, so the
torque of the joint it follows includes its load (τ_j = g_j + multiplier · g_k).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from mpc.core.record import record
from mpc.ir.kinematics import pose_matrix
from mpc.ir.robot import Pose, Robot

_POINT = frozenset({"ball", "revolute", "continuous", "universal", "revolute2"})


class DynamicsError(Exception):
    """The model cannot be built or moved in Pinocchio; the message says why."""


@record
class MimicCoupling:
    """q_follower = multiplier · q_leader + offset; Pinocchio joint ids of one-coordinate joints."""

    follower: int
    leader: int
    multiplier: float
    offset: float


@record(frozen=False)
class Dynamics:
    """A Pinocchio model of a robot, its loop constraints and which joints are actuated.

    actuated: the joints whose torques count: with loops, those with a motor (else those
    its submechanisms name in `jointnames_active`); otherwise every movable joint.
    """

    robot: Robot
    model: Any
    data: Any
    constraints: list[Any]
    actuated: tuple[str, ...]
    mimics: tuple[MimicCoupling, ...] = ()

    # -- configurations ---------------------------------------------------------------------

    def joint_names(self) -> list[str]:
        """The movable joints with one degree of freedom, in Pinocchio's (depth-first) order;
        mimic joints left out (they follow another joint)."""
        m = self.model
        return [m.names[j] for j in range(1, m.njoints) if m.nvs[j] == 1 and m.names[j] not in self.followers]

    @property
    def followers(self) -> frozenset[str]:
        """The mimic joints: their values follow other joints."""
        return _followers(self.robot)

    @property
    def coupled(self) -> bool:
        """Whether q has couplings to satisfy: loop closures or mimic joints."""
        return bool(self.constraints or self.mimics)

    def configuration(self, values: Mapping[str, float],
                      actuated: tuple[str, ...] | None = None) -> np.ndarray:
        """q with `values` by joint name (others at 0), the loops closed by moving the
        joints that are not actuated (Gauss-Newton on the constraint residual).

        actuated: the joints that keep their values (default: this model's actuated ones)."""
        import pinocchio as pin

        m = self.model
        q = pin.neutral(m)
        for name, value in values.items():
            j = m.getJointId(name) if m.existJointName(name) else 0
            if j and m.nvs[j] == 1:
                if m.nqs[j] == 2:  # a continuous joint: (cos, sin) of its angle
                    q[m.idx_qs[j]:m.idx_qs[j] + 2] = np.cos(value), np.sin(value)
                else:
                    q[m.idx_qs[j]] = value
        order = _leaders_first(self.mimics)
        if not self.constraints and order is not None:  # mimic joints alone: set from their joints
            for c in order:
                q[m.idx_qs[c.follower]] = c.multiplier * q[m.idx_qs[c.leader]] + c.offset
            return q
        fixed = {m.idx_vs[m.getJointId(n)] for n in (self.actuated if actuated is None else actuated)
                 if m.existJointName(n) and n not in self.followers}
        free = [i for i in range(m.nv) if i not in fixed]
        for _ in range(50):
            r, J = self.residual(q)
            if np.linalg.norm(r) < 1e-12:
                return q
            step = np.zeros(m.nv)
            step[free] = -np.linalg.lstsq(J[:, free], r, rcond=None)[0]
            q = pin.integrate(m, q, step)
        r, _ = self.residual(q)
        if np.linalg.norm(r) > 1e-6:
            raise DynamicsError(f"the loops do not close at this configuration (residual "
                                f"{np.linalg.norm(r):.3g}): the actuated joints' values are not reachable")
        return q

    def residual(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The loop closures' error (position, and rotation for 6D ones) and the mimic
        couplings' error, and its Jacobian."""
        import pinocchio as pin

        m, d = self.model, self.data
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        errors, rows = [], []
        for c in self.mimics:
            follower, leader = q[m.idx_qs[c.follower]], q[m.idx_qs[c.leader]]
            errors.append(np.array([follower - c.multiplier * leader - c.offset]))
            row = np.zeros((1, m.nv))
            row[0, m.idx_vs[c.follower]], row[0, m.idx_vs[c.leader]] = 1.0, -c.multiplier
            rows.append(row)
        for c in self.constraints:
            A = d.oMi[c.joint1_id] * c.joint1_placement
            B = d.oMi[c.joint2_id] * c.joint2_placement
            JA = pin.getJointJacobian(m, d, c.joint1_id, pin.LOCAL_WORLD_ALIGNED)
            JB = pin.getJointJacobian(m, d, c.joint2_id, pin.LOCAL_WORLD_ALIGNED)
            # velocity of a point p on a body: v_joint + ω × (p - o_joint)
            JpA = JA[:3] - _skew(A.translation - d.oMi[c.joint1_id].translation) @ JA[3:]
            JpB = JB[:3] - _skew(B.translation - d.oMi[c.joint2_id].translation) @ JB[3:]
            errors.append(A.translation - B.translation)
            rows.append(JpA - JpB)
            if c.type == pin.ContactType.CONTACT_6D:
                errors.append(pin.log3(B.rotation.T @ A.rotation))
                rows.append(JA[3:] - JB[3:])
        return np.concatenate(errors), np.vstack(rows)

    # -- quantities ---------------------------------------------------------------------------

    def bodies(self, q: np.ndarray) -> list[tuple[float, np.ndarray]]:
        import pinocchio as pin

        pin.forwardKinematics(self.model, self.data, q)
        out = []
        for j, inertia in enumerate(self.model.inertias):
            X = self.data.oMi[j] if j else pin.SE3.Identity()
            out.append((inertia.mass, X.act(inertia.lever)))
        return out

    def total_mass(self) -> float:
        return float(sum(i.mass for i in self.model.inertias))

    def com(self, q: np.ndarray) -> np.ndarray:
        bodies = self.bodies(q)
        mass = sum(m for m, _ in bodies)
        if mass <= 0:
            return np.zeros(3)
        return sum(m * c for m, c in bodies) / mass  # type: ignore[return-value]

    def link_placements(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """The pose in the root of every link (4×4), at q."""
        import pinocchio as pin

        pin.framesForwardKinematics(self.model, self.data, q)
        return {f.name: self.data.oMf[i].homogeneous.copy() for i, f in enumerate(self.model.frames)
                if f.type == pin.FrameType.BODY}

    def gravity_torques(self, q: np.ndarray, actuated: tuple[str, ...] | None = None) -> dict[str, float]:
        """The actuated joints' (or the given joints') torques that hold q against gravity.

        Without loops: g(q). With loops: g(q) = Sᵀ τ + Jcᵀ λ, solved for τ and the closure
        forces λ together (least squares; exact when the mechanism is statically determined).
        """
        import pinocchio as pin

        m = self.model
        g = pin.computeGeneralizedGravity(m, self.data, q)
        joints = self.actuated if actuated is None else actuated
        index = {n: m.idx_vs[m.getJointId(n)] for n in joints
                 if m.existJointName(n) and m.nvs[m.getJointId(n)] == 1 and n not in self.followers}
        if not self.coupled:
            return {n: float(g[i]) for n, i in index.items()}
        driven = {m.getJointId(n) for n in (*index, *self.actuated) if m.existJointName(n)}
        if not self.constraints and {c.leader for c in self.mimics} <= driven \
                and _leaders_first(self.mimics) is not None:
            return {n: float(self._mimic_load(g, m.getJointId(n))) for n in index}
        _, J = self.residual(q)
        S = np.zeros((m.nv, len(index)))
        for k, i in enumerate(index.values()):
            S[i, k] = 1.0
        A = np.hstack([S, J.T])
        x = np.linalg.lstsq(A, g, rcond=None)[0]
        scale = max(1.0, float(np.linalg.norm(g)))
        if np.linalg.norm(A @ x - g) > 1e-8 * scale:
            raise DynamicsError(f"the actuated joints ({', '.join(index)}) cannot hold this configuration "
                                "against gravity: the mechanism has a motion none of them drives")
        # τ is unique when no combination of closure forces and torques balances to zero
        # with a torque in it: the null space of A has no τ component.
        _, sv, vt = np.linalg.svd(A)
        rank = int(np.sum(sv > 1e-10 * sv[0])) if sv.size else 0
        null = vt[rank:, :len(index)]
        if null.size and np.max(np.abs(null)) > 1e-8:
            hint = "" if self.robot.motors else (": without motors every movable joint counts as "
                                                 "actuated; mark the driven ones `active: true` in `joints`")
            raise DynamicsError(f"the actuated joints ({', '.join(index)}) do not determine their torques "
                                f"(the mechanism is overactuated{hint})")
        return {n: float(x[k]) for k, n in enumerate(index)}

    def _mimic_load(self, g: np.ndarray, joint: int) -> float:
        """The gravity load on a joint with the loads of the joints that follow it (mimic):
        g_j + Σ multiplier · load_follower, the principle of virtual work, recursively (a
        follower may be followed). The closed form of the least squares below when there
        is no loop and every followed joint is actuated (or asked for)."""
        load = float(g[self.model.idx_vs[joint]])
        for c in self.mimics:
            if c.leader == joint:
                load += c.multiplier * self._mimic_load(g, c.follower)
        return load


def _leaders_first(mimics: tuple[MimicCoupling, ...]) -> list[MimicCoupling] | None:
    """The couplings ordered so that a follower that is itself followed is set first; None
    when they make a cycle (then the general solution, Gauss-Newton, is left to judge them)."""
    out: list[MimicCoupling] = []
    rest = list(mimics)
    followers = {c.follower for c in mimics}
    while rest:
        ready = [c for c in rest if c.leader not in followers or c.leader in {d.follower for d in out}]
        if not ready:
            return None
        out += ready
        taken = set(map(id, ready))  # by identity: field by field cost effort_covers_gravity 50 ms (TALOS)
        rest = [c for c in rest if id(c) not in taken]
    return out


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def build(robot: Robot) -> Dynamics:
    """The Pinocchio model of `robot` (fixed base), with a constraint per cut joint."""
    import pinocchio as pin

    from mpc.backends.urdf_writer import to_string
    from mpc.checks.console import captured_fds

    text = to_string(_with_full_limits(robot), lambda mesh: "mesh.stl")  # no mesh is read
    with captured_fds() as console:  # urdfdom prints its errors from C
        try:
            model = pin.buildModelFromXML(text)
            problem = ""
        except (RuntimeError, ValueError) as e:
            problem = str(e)
    if problem:
        said = " ".join(ln.strip() for ln in console[0].splitlines() if ln.strip().startswith("Error:"))
        raise DynamicsError(f"Pinocchio cannot build the model: {problem}" + (f" ({said})" if said else ""))
    constraints = []
    for cut in sorted(robot.cut_joints.values(), key=lambda c: c.name):
        constraints.append(_constraint(pin, model, robot, cut))
    mimics = _mimic_couplings(model, robot)
    followers = _followers(robot)
    movable = [model.names[j] for j in range(1, model.njoints)
               if model.nvs[j] == 1 and model.names[j] not in followers]
    motors = {m.joint for m in robot.motors.values()} or _active_in_submechanisms(robot)
    actuated = [n for n in movable if n in motors] if constraints and motors else movable
    return Dynamics(robot=robot, model=model, data=model.createData(), constraints=constraints,
                    actuated=tuple(actuated), mimics=mimics)


def _followers(robot: Robot) -> frozenset[str]:
    return frozenset(j.name for j in robot.joints.values() if j.mimic is not None)


def _mimic_couplings(model: Any, robot: Robot) -> tuple[MimicCoupling, ...]:
    """The couplings of the robot's mimic joints (revolute and prismatic ones)."""
    out = []
    for joint in sorted(robot.joints.values(), key=lambda j: j.name):
        if joint.mimic is None:
            continue
        ids = []
        for name in (joint.name, joint.mimic.joint):
            jid = model.getJointId(name) if model.existJointName(name) else 0
            if not jid or model.nqs[jid] != 1 or model.nvs[jid] != 1:
                raise DynamicsError(f"mimic joint '{joint.name}' follows '{joint.mimic.joint}': only "
                                    "revolute and prismatic joints can be coupled")
            ids.append(jid)
        multiplier = 1.0 if joint.mimic.multiplier is None else joint.mimic.multiplier
        offset = 0.0 if joint.mimic.offset is None else joint.mimic.offset
        out.append(MimicCoupling(follower=ids[0], leader=ids[1], multiplier=multiplier, offset=offset))
    return tuple(out)


def _active_in_submechanisms(robot: Robot) -> set[str]:
    """The joints the submechanisms name as active (HyRoDyn's `jointnames_active`)."""
    out: set[str] = set()
    for sub in robot.submechanisms:
        names = sub.definition.get("jointnames_active") if isinstance(sub.definition, Mapping) else None
        if isinstance(names, list | tuple):
            out.update(n for n in names if isinstance(n, str))
    return out


def _with_full_limits(robot: Robot) -> Robot:
    """urdfdom refuses a limit without effort or velocity (SDF models often have none);
    dynamics does not use them, so they are filled with 0 for Pinocchio's parser."""
    from dataclasses import replace

    joints = {}
    for name, j in robot.joints.items():
        if j.limit is not None and (j.limit.effort is None or j.limit.velocity is None):
            limit = replace(j.limit, effort=j.limit.effort or 0.0, velocity=j.limit.velocity or 0.0)
            j = replace(j, limit=limit)
        joints[name] = j
    return replace(robot, joints=joints)


def _constraint(pin: Any, model: Any, robot: Robot, cut: Any) -> Any:
    """The RigidConstraintModel of a cut joint: its frame on the child (the child link's
    frame, or `joint_origin` from an SDF), and the same frame on the parent at q = 0."""
    if cut.type not in _POINT and cut.type != "fixed":
        raise DynamicsError(f"cut joint '{cut.name}' is {cut.type}; loop closures of this type "
                            "are not modelled (fixed, ball, revolute, continuous, universal are)")
    X_CJ = np.eye(4)
    jo = cut.annotations.get("joint_origin") if isinstance(cut.annotations, Mapping) else None
    if isinstance(jo, Mapping):
        X_CJ = pose_matrix(Pose(tuple(jo.get("xyz", (0, 0, 0))), tuple(jo.get("rpy", (0, 0, 0)))))
    X_PJ = pose_matrix(cut.origin) @ X_CJ
    ends = []
    for link, X_LJ in ((cut.parent, X_PJ), (cut.child, X_CJ)):
        fid = model.getFrameId(link, pin.FrameType.BODY)
        if fid >= len(model.frames):
            raise DynamicsError(f"cut joint '{cut.name}' names link '{link}', which the model lacks")
        frame = model.frames[fid]
        ends.append((frame.parentJoint, frame.placement * pin.SE3(X_LJ)))
    kind = pin.ContactType.CONTACT_6D if cut.type == "fixed" else pin.ContactType.CONTACT_3D
    c = pin.RigidConstraintModel(kind, model, ends[0][0], ends[0][1], ends[1][0], ends[1][1],
                                 pin.LOCAL_WORLD_ALIGNED)
    c.name = cut.name
    return c
