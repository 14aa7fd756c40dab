"""Homogeneous transforms: xyz/rpy ↔ 4×4 matrices, composition, inverse.

Conventions are URDF's: rpy are fixed-axis roll (x), pitch (y), yaw (z), so
R = Rz(yaw) · Ry(pitch) · Rx(roll). Names follow Drake's monograms: `X_PC` is the
pose of frame C in frame P.
"""

from __future__ import annotations

import math

import numpy as np

Vec3 = tuple[float, float, float]


def rpy_to_matrix(rpy: Vec3) -> np.ndarray:
    """The 3×3 rotation of fixed-axis roll, pitch, yaw."""
    r, p, y = rpy
    cr, sr = math.cos(r), math.sin(r)
    cp, sp = math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_to_rpy(R: np.ndarray) -> Vec3:
    """Fixed-axis roll, pitch, yaw of a rotation matrix (pitch in [-pi/2, pi/2]).

    Pitch comes from atan2 (not asin) and roll from what yaw and pitch leave of R, so the
    angles reproduce R to rounding also near pitch ±π/2 (an asin with a gimbal-lock band
    moved frames there by up to 1e-6 rad).
    """
    yaw = math.atan2(float(R[1, 0]), float(R[0, 0]))
    pitch = math.atan2(-float(R[2, 0]), math.hypot(float(R[0, 0]), float(R[1, 0])))
    M = rpy_to_matrix((0.0, pitch, yaw)).T @ R
    return (math.atan2(float(M[2, 1]), float(M[1, 1])), pitch, yaw)


def pose_to_matrix(xyz: Vec3, rpy: Vec3) -> np.ndarray:
    """X_PC as a 4×4 matrix from C's origin in P (xyz) and orientation (rpy)."""
    X = np.eye(4)
    X[:3, :3] = rpy_to_matrix(rpy)
    X[:3, 3] = xyz
    return X


def matrix_to_pose(X: np.ndarray) -> tuple[Vec3, Vec3]:
    """(xyz, rpy) of a 4×4 homogeneous transform."""
    xyz = (float(X[0, 3]), float(X[1, 3]), float(X[2, 3]))
    return xyz, matrix_to_rpy(X[:3, :3])


def inverse(X: np.ndarray) -> np.ndarray:
    """X_CP from X_PC, using the orthonormality of the rotation."""
    R = X[:3, :3]
    Xi = np.eye(4)
    Xi[:3, :3] = R.T
    Xi[:3, 3] = -R.T @ X[:3, 3]
    return Xi


def compose(*Xs: np.ndarray) -> np.ndarray:
    """X_AD = X_AB · X_BC · X_CD."""
    out = np.eye(4)
    for X in Xs:
        out = out @ X
    return out


def matrix_to_quat(R: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) of a rotation matrix, w ≥ 0, by the method of SciPy's
    `Rotation.from_matrix` (Markley's: built on the largest of the diagonal and the trace), in
    Python's floats and in SciPy's order of operations, so that the digits are SciPy's: the
    outputs written with SciPy keep their bytes, without SciPy's 0.2–2 s of imports."""
    m = [[float(R[i][j]) for j in range(3)] for i in range(3)]
    trace = m[0][0] + m[1][1] + m[2][2]
    decision = (m[0][0], m[1][1], m[2][2], trace)
    choice = max(range(4), key=lambda c: (decision[c], -c))  # the first of equals, as argmax
    q = [0.0, 0.0, 0.0, 0.0]  # x, y, z, w
    if choice == 3:
        q = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1], 1 + trace]
    else:
        i = choice
        j, k = (i + 1) % 3, (i + 2) % 3
        q[i] = 1 - trace + 2 * m[i][i]
        q[j] = m[j][i] + m[i][j]
        q[k] = m[k][i] + m[i][k]
        q[3] = m[k][j] - m[j][k]
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    x, y, z, w = (c / norm for c in q)
    return (w, x, y, z) if w >= 0 else (-w, -x, -y, -z)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a quaternion (w, x, y, z), normalised first (MJCF's convention)."""
    w, x, y, z = (float(v) for v in q / np.linalg.norm(q))
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
