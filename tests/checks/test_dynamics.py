"""The dynamics model of the checks against Pinocchio used directly (free-flyer root, so the
root link counts), and continuous joints moved like revolute ones."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from mpc.backends.urdf_reader import read
from mpc.checks.dynamics_model import build
from mpc.core.diagnostics import Sink
from tests.backends.pin_compare import load
from tests.conftest import ERD


@pytest.mark.parametrize("model", ["talos_data/robots/talos_full_v2.urdf",
                                   "solo_description/robots/solo12.urdf"])
def test_mass_com_and_placements_are_pinocchios(model: str) -> None:
    robot = read(ERD / model, Sink())
    assert robot is not None
    dyn = build(robot)
    free = load(ERD / model)  # free-flyer root at the origin: the same placements
    data = free.createData()
    assert dyn.total_mass() == pytest.approx(pin.computeTotalMass(free), abs=1e-12)
    q = dyn.configuration(dict.fromkeys(dyn.joint_names(), 0.3))
    q_free = np.concatenate([[0, 0, 0, 0, 0, 0, 1], q])
    np.testing.assert_allclose(dyn.com(q), pin.centerOfMass(free, data, q_free), atol=1e-12)
    pin.framesForwardKinematics(free, data, q_free)
    placements = dyn.link_placements(q)
    for name, X in placements.items():
        np.testing.assert_allclose(X, data.oMf[free.getFrameId(name, pin.FrameType.BODY)].homogeneous,
                                   atol=1e-12, err_msg=name)
    assert len(placements) == len(robot.links)


def test_continuous_joints_move_like_revolute_ones() -> None:
    folder = ERD / "double_pendulum_description/urdf"
    continuous = build(read(folder / "double_pendulum_continuous.urdf", Sink()))
    revolute = build(read(folder / "double_pendulum.urdf", Sink()))
    assert continuous.model.nq == 4 and revolute.model.nq == 2
    values = {"joint1": 0.5, "joint2": -1.2}
    tau_c = continuous.gravity_torques(continuous.configuration(values))
    tau_r = revolute.gravity_torques(revolute.configuration(values))
    assert tau_c == pytest.approx(tau_r, abs=1e-12)
    assert abs(tau_r["joint1"]) > 0.005  # not a trivial zero


MIMIC_URDF = """\
<robot name="gripper">
  <link name="a"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <link name="b"><inertial><origin xyz="0 0.1 0.3"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="k" type="revolute"><origin xyz="0 0 1"/><parent link="b"/><child link="c"/>
    <axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
    <mimic joint="j" multiplier="2" offset="0.1"/></joint>
  <link name="c"><inertial><origin xyz="0 0.2 0.5"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>
"""


def test_a_mimic_joint_follows_and_its_load_is_on_the_joint_it_follows(tmp_path) -> None:
    """q_k = 2 q_j + 0.1; the torque that holds j is dV/dθ of the potential energy along the
    coupled motion (a finite difference of Pinocchio's potential energy)."""
    (tmp_path / "g.urdf").write_text(MIMIC_URDF)
    robot = read(tmp_path / "g.urdf", Sink())
    assert robot is not None
    dyn = build(robot)
    assert (dyn.joint_names(), dyn.actuated) == (["j"], ("j",))
    theta = 0.4
    q = dyn.configuration({"j": theta, "k": 5.0})  # k's own value is ignored: it follows j
    np.testing.assert_allclose(q, [theta, 2 * theta + 0.1], atol=1e-12)

    def potential(t: float) -> float:
        return pin.computePotentialEnergy(dyn.model, dyn.data, np.array([t, 2 * t + 0.1]))

    h = 1e-6
    expected = (potential(theta + h) - potential(theta - h)) / (2 * h)
    tau = dyn.gravity_torques(q)
    assert list(tau) == ["j"]
    assert tau["j"] == pytest.approx(expected, abs=1e-6)
    assert abs(tau["j"] - pin.computeGeneralizedGravity(dyn.model, dyn.data, q)[0]) > 1.0  # k's load counts


def test_a_mimic_joint_that_is_followed_passes_its_load_on(tmp_path) -> None:
    """A chain of mimics: k follows j (q_k = 2 q_j + 0.1), l follows k (q_l = -q_k); the load
    of both is on j (a finite difference of the potential energy along the coupled motion)."""
    chained = MIMIC_URDF.replace("</robot>", """\
  <joint name="l" type="revolute"><origin xyz="0 0 1"/><parent link="c"/><child link="d"/>
    <axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
    <mimic joint="k" multiplier="-1" offset="0"/></joint>
  <link name="d"><inertial><origin xyz="0 0.3 0.2"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>""")
    (tmp_path / "g.urdf").write_text(chained)
    robot = read(tmp_path / "g.urdf", Sink())
    assert robot is not None
    dyn = build(robot)
    theta = 0.4
    q = dyn.configuration({"j": theta})
    np.testing.assert_allclose(q, [theta, 2 * theta + 0.1, -(2 * theta + 0.1)], atol=1e-12)

    def potential(t: float) -> float:
        return pin.computePotentialEnergy(dyn.model, dyn.data, np.array([t, 2 * t + 0.1, -(2 * t + 0.1)]))

    h = 1e-6
    expected = (potential(theta + h) - potential(theta - h)) / (2 * h)
    assert dyn.gravity_torques(q)["j"] == pytest.approx(expected, abs=1e-6)
