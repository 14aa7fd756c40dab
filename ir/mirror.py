"""Mirror a robot at a plane through its root: the geometry of `ir.ops.Mirror`.

Let M = I − 2nnᵀ be the reflection at the plane with normal n, and F the reflection
of the frame axis that is flipped afterwards (`flip_axis`) so frames stay right-handed.
A link frame L with pose (R, p) in the root becomes (M R F, M p); the root frame stays.
It follows that each joint origin X_PC = (R, p) becomes (S_P R F, S_P p) with S_P = M
for children of the root and S_P = F below them; everything expressed in a link frame
(visual, collision and inertial origins, COMs, sensor frames) is reflected with that
link's S. Shapes are reflected along the flip axis in their own frame: primitives are
symmetric under it, meshes get a ReflectMesh op.

Joint axes are reflected as directions, a' = F a (Phobos's convention): a revolute
joint of the mirror at −q is the mirror image of the original at q, a prismatic one at
+q. Position limits, calibration and soft limits of revolute and continuous joints are
therefore negated and swapped, and mimic offsets follow, so the mirror can reach
exactly the mirror images of the original's configurations.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mpc.ir import transforms as tf
from mpc.ir.geometry import Mesh, ReflectMesh
from mpc.ir.robot import Calibration, Inertia, Inertial, Joint, Link, Mimic, Pose, Robot

_ROTATING = ("revolute", "continuous")


def reflection(normal: tuple[float, float, float]) -> np.ndarray:
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    return np.eye(3) - 2.0 * np.outer(n, n)


def axis_flip(axis: int) -> np.ndarray:
    F = np.eye(3)
    F[axis, axis] = -1.0
    return F


def _pose(pose: Pose | None, S: np.ndarray, F: np.ndarray) -> Pose | None:
    if pose is None:
        return None
    R = tf.rpy_to_matrix(pose.rpy)
    xyz = tuple(float(x) for x in S @ np.asarray(pose.xyz))
    rpy = tf.matrix_to_rpy(S @ R @ F)
    return Pose(_clean(xyz), _clean(rpy), (True, True))  # type: ignore[arg-type]


def _clean(v: tuple[float, ...]) -> tuple[float, ...]:
    """-0.0 → 0.0, so mirrored files do not differ from hand-written ones by signs of zero."""
    return tuple(0.0 if x == 0 else x for x in v)


def _inertial(inertial: Inertial | None, S: np.ndarray, F: np.ndarray) -> Inertial | None:
    if inertial is None:
        return None
    i = inertial.inertia
    I_ = np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])
    origin = inertial.origin or Pose()
    # The tensor in the new inertial frame (rotation S R F): F I F.
    J = F @ I_ @ F
    return replace(inertial, origin=_pose(origin, S, F),
                   inertia=Inertia(ixx=float(J[0, 0]), ixy=float(J[0, 1]), ixz=float(J[0, 2]),
                                   iyy=float(J[1, 1]), iyz=float(J[1, 2]), izz=float(J[2, 2])))


def _shape(item, S: np.ndarray, F: np.ndarray, axis: int, exclude: frozenset[str]):
    geometry = item.geometry
    if isinstance(geometry, Mesh):
        stem = (geometry.source.path.name if geometry.source.path else geometry.source.uri)
        if "ALL" not in exclude and stem not in exclude and stem.rsplit(".", 1)[0] not in exclude:
            geometry = replace(geometry, ops=(*geometry.ops, ReflectMesh(axis)))
    return replace(item, origin=_pose(item.origin or Pose(), S, F), geometry=geometry)


def _negate_range(lo: float | None, hi: float | None) -> tuple[float | None, float | None]:
    return (None if hi is None else -hi, None if lo is None else -lo)


def _joint(joint: Joint, S: np.ndarray, F: np.ndarray, rotating: dict[str, bool]) -> Joint:
    axis = joint.axis if joint.axis is not None else (1.0, 0.0, 0.0)
    new_axis = _clean(tuple(float(x) for x in F @ np.asarray(axis)))
    out = replace(joint, origin=_pose(joint.origin or Pose(), S, F),
                  axis=new_axis if joint.type not in ("fixed", "floating") else joint.axis)
    if joint.mimic is not None:
        # q_m = k q_t + c, and q' = s q (s = -1 for rotating joints): k' = s_m s_t k, c' = s_m c.
        m = joint.mimic
        s_m = -1.0 if rotating[joint.name] else 1.0
        s_t = -1.0 if rotating.get(m.joint, False) else 1.0
        k = m.multiplier if m.multiplier is not None else 1.0
        out = replace(out, mimic=Mimic(joint=m.joint, multiplier=s_m * s_t * k if s_m * s_t < 0
                                       else m.multiplier,
                                       offset=None if m.offset is None else s_m * m.offset))
    if joint.type not in _ROTATING:
        return out
    if joint.limit is not None:
        lo, hi = _negate_range(joint.limit.lower, joint.limit.upper)
        out = replace(out, limit=replace(joint.limit, lower=lo, upper=hi))
    if joint.safety_controller is not None:
        sc = joint.safety_controller
        lo, hi = _negate_range(sc.soft_lower_limit, sc.soft_upper_limit)
        out = replace(out, safety_controller=replace(sc, soft_lower_limit=lo, soft_upper_limit=hi))
    if joint.calibration is not None:
        c = joint.calibration
        neg = (lambda x: None if x is None else -x)  # noqa: E731
        out = replace(out, calibration=Calibration(rising=neg(c.falling), falling=neg(c.rising),
                                                   reference_position=neg(c.reference_position)))
    return out


def mirror_robot(robot: Robot, plane: tuple[float, float, float], flip_axis: int,
                 exclude_meshes: tuple[str, ...] = ()) -> Robot:
    """The mirror image of `robot` (see the module docstring)."""
    M, F = reflection(plane), axis_flip(flip_axis)
    exclude = frozenset(exclude_meshes)
    rotating = {n: j.type in _ROTATING for n, j in robot.joints.items()}

    def S(link: str) -> np.ndarray:
        return M if link == robot.root else F

    links: dict[str, Link] = {}
    for name, link in robot.links.items():
        s = S(name)
        links[name] = replace(
            link, inertial=_inertial(link.inertial, s, F),
            visuals=tuple(_shape(v, s, F, flip_axis, exclude) for v in link.visuals),
            collisions=tuple(_shape(c, s, F, flip_axis, exclude) for c in link.collisions))
    joints = {n: _joint(j, S(j.parent), F, rotating) for n, j in robot.joints.items()}
    return replace(robot, links=links, joints=joints)
