"""Link poses at the zero configuration: X_RL, the pose of link L in the root frame R."""

from __future__ import annotations

import math

import numpy as np

from mpc.ir import transforms as tf
from mpc.ir.robot import Joint, Pose, Robot
from mpc.ir.tree import depth_first, joints_up


def pose_matrix(pose: Pose | None) -> np.ndarray:
    return np.eye(4) if pose is None else tf.pose_to_matrix(pose.xyz, pose.rpy)


def link_in_root(robot: Robot, link: str) -> np.ndarray:
    """X_RL at q = 0: the product of the joint origins from the root down to `link`."""
    chain = [pose_matrix(joint.origin) for joint in joints_up(robot, link)]
    return tf.compose(*reversed(chain)) if chain else np.eye(4)


def links_in_root(robot: Robot) -> dict[str, np.ndarray]:
    """X_RL of every link at q = 0, from the root down: linear in the number of links, where
    `link_in_root` for each link is quadratic in the tree's depth. The products are the same,
    in the same order, so the numbers equal `link_in_root`'s to the bit."""
    X_R: dict[str, np.ndarray] = {}
    for joint, link in depth_first(robot):
        X_R[link] = np.eye(4) if joint is None else X_R[joint.parent] @ pose_matrix(joint.origin)
    return X_R


def matrix_pose(X: np.ndarray) -> Pose:
    xyz, rpy = tf.matrix_to_pose(X)
    return Pose(xyz, rpy)


def compose_poses(*poses: Pose | None) -> Pose:
    """X_AC from X_AB, X_BC, … (None is the identity)."""
    return matrix_pose(tf.compose(*(pose_matrix(p) for p in poses)))


def inverse_pose(pose: Pose | None) -> Pose:
    return matrix_pose(tf.inverse(pose_matrix(pose)))


def joint_range(joint: Joint) -> tuple[float, float]:
    """The values a joint is drawn at (`mpc view`'s sliders, the pictures' zero pose): its
    limits, ±π for a continuous joint (or one without limits), ±1 m for a prismatic joint
    without limits."""
    lim = joint.limit
    if joint.type != "continuous" and lim is not None and lim.lower is not None and lim.upper is not None \
            and lim.lower < lim.upper:
        return lim.lower, lim.upper
    return (-1.0, 1.0) if joint.type == "prismatic" else (-math.pi, math.pi)


def zero_within_limits(robot: Robot) -> dict[str, float]:
    """The joints whose limits leave out 0, each at the value of its range nearest 0 (as
    `mpc view`'s sliders start): the zero pose a picture can draw. Mimic joints follow
    their joint and are not listed."""
    out = {}
    for joint in robot.joints.values():
        if joint.type in ("revolute", "prismatic") and joint.mimic is None:
            low, high = joint_range(joint)
            value = min(max(0.0, low), high)
            if value != 0.0:
                out[joint.name] = value
    return out
