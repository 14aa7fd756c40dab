"""Transforms follow URDF's convention, checked against Pinocchio's own rpy functions."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from hypothesis import given
from hypothesis import strategies as st

from mpc.ir import transforms as tf

angle = st.floats(min_value=-np.pi, max_value=np.pi, allow_nan=False)
coord = st.floats(min_value=-10, max_value=10, allow_nan=False)


@given(angle, angle, angle)
def test_rpy_matches_pinocchio(r: float, p: float, y: float) -> None:
    np.testing.assert_allclose(tf.rpy_to_matrix((r, p, y)), pin.rpy.rpyToMatrix(r, p, y),
                               atol=1e-15)


@given(angle, st.floats(min_value=-1.5, max_value=1.5), angle)
def test_rpy_round_trip(r: float, p: float, y: float) -> None:
    R = tf.rpy_to_matrix((r, p, y))
    np.testing.assert_allclose(tf.rpy_to_matrix(tf.matrix_to_rpy(R)), R, atol=1e-12)


def test_gimbal_lock_keeps_the_rotation() -> None:
    R = tf.rpy_to_matrix((0.3, np.pi / 2, -0.2))
    np.testing.assert_allclose(tf.rpy_to_matrix(tf.matrix_to_rpy(R)), R, atol=1e-12)


@given(st.tuples(coord, coord, coord), st.tuples(angle, angle, angle))
def test_inverse_and_compose(xyz: tuple, rpy: tuple) -> None:
    X = tf.pose_to_matrix(xyz, rpy)
    np.testing.assert_allclose(tf.compose(X, tf.inverse(X)), np.eye(4), atol=1e-12)
    back_xyz, back_rpy = tf.matrix_to_pose(X)
    np.testing.assert_allclose(tf.pose_to_matrix(back_xyz, back_rpy), X, atol=1e-12)


def test_matrix_to_quat_has_scipys_digits() -> None:
    """The MJCF and USD writers' quaternions are SciPy's `Rotation.from_matrix`, to the last bit
    (the files written before SciPy was dropped keep their bytes): on principal frames of random
    inertias, on the 24 axis-aligned rotations (where the largest of diagonal and trace ties), and
    with w < 0 turned to w ≥ 0 as the writers did."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(2026)
    matrices = []
    for _ in range(3000):
        a = rng.normal(size=(3, 3))
        V = np.linalg.eigh(a + a.T)[1]
        V[:, 2] *= np.sign(np.linalg.det(V))
        matrices.append(V)
    quarter = (0.0, np.pi / 2, np.pi, -np.pi / 2)
    matrices += [Rotation.from_euler("xyz", (r, p, y)).as_matrix()
                 for r in quarter for p in quarter for y in quarter]
    for R in matrices:
        x, y, z, w = (float(c) for c in Rotation.from_matrix(R).as_quat())
        assert tf.matrix_to_quat(R) == ((w, x, y, z) if w >= 0 else (-w, -x, -y, -z))


@given(angle, angle, angle)
def test_quat_to_matrix_inverts_matrix_to_quat(r: float, p: float, y: float) -> None:
    R = tf.rpy_to_matrix((r, p, y))
    np.testing.assert_allclose(tf.quat_to_matrix(np.array(tf.matrix_to_quat(R))), R, atol=1e-12)
