"""Link poses at the zero configuration: X_RL, the pose of link L in the root frame R."""

from __future__ import annotations

import numpy as np

from mpc.ir import transforms as tf
from mpc.ir.robot import Pose, Robot
from mpc.ir.tree import joints_up


def pose_matrix(pose: Pose | None) -> np.ndarray:
    return np.eye(4) if pose is None else tf.pose_to_matrix(pose.xyz, pose.rpy)


def link_in_root(robot: Robot, link: str) -> np.ndarray:
    """X_RL at q = 0: the product of the joint origins from the root down to `link`."""
    chain = [pose_matrix(joint.origin) for joint in joints_up(robot, link)]
    return tf.compose(*reversed(chain)) if chain else np.eye(4)


def matrix_pose(X: np.ndarray) -> Pose:
    xyz, rpy = tf.matrix_to_pose(X)
    return Pose(xyz, rpy)


def compose_poses(*poses: Pose | None) -> Pose:
    """X_AC from X_AB, X_BC, … (None is the identity)."""
    return matrix_pose(tf.compose(*(pose_matrix(p) for p in poses)))


def inverse_pose(pose: Pose | None) -> Pose:
    return matrix_pose(tf.inverse(pose_matrix(pose)))
