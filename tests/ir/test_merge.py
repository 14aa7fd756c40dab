"""ir/merge.py: merging a joint away keeps the data that named it right."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from mpc.backends.urdf_reader import read
from mpc.core.diagnostics import Severity
from mpc.core.span import Span
from mpc.ir.extras import CutJoint, Motor, Sensor, Submechanism
from mpc.ir.merge import merge_joints
from mpc.ir.robot import Pose, Robot
from tests.conftest import Diags
from tests.fixtures import arm

SPAN = Span("m.yml", 1, 1, 1, 2)


def arm_with_extras(tmp_path: Path, diags: Diags) -> Robot:
    robot = read(arm(tmp_path), diags)
    assert robot is not None
    return replace(
        robot,
        motors={"m_shoulder": Motor(name="m_shoulder", joint="shoulder"),
                "m_elbow": Motor(name="m_elbow", joint="elbow")},
        poses={"home": {"shoulder": 0.5, "elbow": 1.0}},
        sensors={"cam": Sensor(name="cam", type="CameraSensor", link="lower", position_offset=(0.0, 0.0, 0.1),
                               orientation_offset=(0.0, 0.0, 0.0)),
                 "enc": Sensor(name="enc", type="JointPosition", joint="elbow")},
        # A loop from base to lower, closed at q = 0: lower is 0.5 m above base.
        cut_joints={"loop": CutJoint(name="loop", type="spherical", parent="base", child="lower",
                                     origin=Pose((0.0, 0.0, 0.5), (0.0, 0.0, 0.0)))},
        submechanisms=(Submechanism(name="s", definition={"name": "s", "jointnames_spanningtree": ["elbow"]}),
                       Submechanism(name="t", definition={
                           "name": "t", "jointnames_spanningtree": ["shoulder", "elbow"],
                           "jointnames_independent": ["shoulder"]})),
    )


def test_what_names_a_merged_joint_follows(tmp_path: Path, diags: Diags) -> None:
    """Merging `elbow` away: `lower` joins `upper`; the elbow's motor, pose entry and joint
    sensor go (W0521); the camera on `lower` moves to `upper` 0.4 m further out; the loop
    now closes on `upper`, 0.1 m above base; submechanism `s` (only the elbow) goes, `t`
    keeps the shoulder."""
    merged = merge_joints(arm_with_extras(tmp_path, diags), ["elbow"], diags, SPAN)
    assert merged is not None
    assert diags.take("W0521", Severity.WARNING).message == \
        "sensor 'enc' is on joint 'elbow', which is merged away; it is left out"
    assert set(merged.links) == {"base", "upper"} and set(merged.joints) == {"shoulder"}
    assert merged.motors.keys() == {"m_shoulder"} and merged.poses == {"home": {"shoulder": 0.5}}
    cam = merged.sensors["cam"]
    assert set(merged.sensors) == {"cam"} and cam.link == "upper"
    assert np.allclose(cam.position_offset, (0, 0, 0.5)) and np.allclose(cam.orientation_offset, 0)
    loop = merged.cut_joints["loop"]
    assert (loop.parent, loop.child) == ("base", "upper")
    assert np.allclose(loop.origin.xyz, (0, 0, 0.1), atol=1e-12) and np.allclose(loop.origin.rpy, 0)
    assert [sm.name for sm in merged.submechanisms] == ["t"]
    assert merged.submechanisms[0].definition == {"name": "t", "jointnames_spanningtree": ["shoulder"],
                                                  "jointnames_independent": ["shoulder"]}
    # Mass properties: the upper link now carries the lower one (0.5 kg at its origin, 0.4 m up).
    upper = merged.links["upper"].inertial
    assert upper is not None and np.isclose(upper.mass, 1.5)
    assert np.allclose(upper.origin.xyz, (0, 0, (1 * 0.2 + 0.5 * 0.4) / 1.5))


def test_a_kept_joint_that_mimics_a_merged_one(tmp_path: Path, diags: Diags) -> None:
    from mpc.ir.robot import Mimic

    robot = arm_with_extras(tmp_path, diags)
    robot = replace(robot, joints={**robot.joints, "elbow": replace(robot.joints["elbow"],
                                                                    mimic=Mimic(joint="shoulder"))})
    assert merge_joints(robot, ["shoulder"], diags, SPAN) is None
    assert diags.take_error("E0319").message == "cannot remove joint 'shoulder': joint 'elbow' mimics it"
