"""Mass properties: an Inertial as (mass, COM, inertia about the COM) in a link frame, and
the composite of several bodies (parallel-axis theorem)."""

from __future__ import annotations

import numpy as np

from mpc.core.record import record
from mpc.ir.kinematics import pose_matrix
from mpc.ir.robot import Inertia, Inertial, Pose


@record
class Body:
    """mass (kg); com: p_LoBcm_L (m); I: the inertia about the COM, in frame L (kg·m²)."""

    mass: float
    com: np.ndarray
    I: np.ndarray  # noqa: E741 - the usual name


def body(inertial: Inertial | None, X_FL: Pose | None = None) -> Body:
    """The body of `inertial` (given in link frame L) expressed in frame F."""
    if inertial is None:
        return Body(0.0, np.zeros(3), np.zeros((3, 3)))
    i = inertial.inertia
    I_c = np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])
    X = pose_matrix(X_FL) @ pose_matrix(inertial.origin)
    R = X[:3, :3]
    return Body(inertial.mass, X[:3, 3].copy(), R @ I_c @ R.T)


def combine(*bodies: Body) -> Body:
    """The composite body: total mass, mass-weighted COM, inertia about that COM."""
    mass = sum(b.mass for b in bodies)
    if mass == 0.0:
        return Body(0.0, np.zeros(3), sum((b.I for b in bodies), np.zeros((3, 3))))
    com = sum(b.mass * b.com for b in bodies) / mass
    I_ = np.zeros((3, 3))
    for b in bodies:
        d = b.com - com
        I_ += b.I + b.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return Body(mass, com, I_)


def inertial(b: Body) -> Inertial:
    """An Inertial with the COM frame parallel to the link frame."""
    I_ = b.I
    return Inertial(mass=float(b.mass), origin=Pose(tuple(float(x) for x in b.com), (0.0, 0.0, 0.0)),  # type: ignore[arg-type]
                    inertia=Inertia(ixx=float(I_[0, 0]), ixy=float(I_[0, 1]), ixz=float(I_[0, 2]),
                                    iyy=float(I_[1, 1]), iyz=float(I_[1, 2]), izz=float(I_[2, 2])))


def placed(b: Body, X: np.ndarray) -> Body:
    """The body `b` (props in its own frame) placed by the 4×4 pose X of that frame."""
    R = X[:3, :3]
    return Body(b.mass, R @ b.com + X[:3, 3], R @ b.I @ R.T)


def principal(b: Body) -> np.ndarray:
    """Principal moments, ascending."""
    return np.linalg.eigvalsh(b.I)
