"""Loop closures in MJCF close where the source closes them: Cassie's four rods (SDF, ball
joints that sit off their child's origin) and a four-bar written here, loaded in MuJoCo and
compared with Pinocchio's constrained model (mpc.checks.dynamics_model): the closure points
coincide at configurations where Pinocchio's loops are closed, and the torques that hold the
closed mechanism against gravity are the same."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest

from mpc.backends import mjcf, sdf_reader
from mpc.checks.dynamics_model import Dynamics, build
from mpc.core.diagnostics import Severity
from mpc.ir.extras import Motor
from mpc.ir.robot import Pose, Robot
from tests.checks.fourbar import FOURBAR_DEFINITION, FOURBAR_URDF
from tests.checks.helpers import compile_ok
from tests.checks.test_loops import cassie_definition
from tests.conftest import Diags, write

MJCF_EXPORT = "    - type: mjcf\n      mesh_format: stl\n"


def mujoco_qpos(model: mujoco.MjModel, dyn: Dynamics, q: np.ndarray) -> np.ndarray:
    """Pinocchio's q as MuJoCo's qpos, joint by joint name (a continuous joint is (cos, sin))."""
    pm = dyn.model
    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        assert int(model.jnt_type[j]) in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
        i = pm.getJointId(model.joint(j).name)
        assert i < pm.njoints, model.joint(j).name
        a = pm.idx_qs[i]
        qpos[model.jnt_qposadr[j]] = np.arctan2(q[a + 1], q[a]) if pm.nqs[i] == 2 else q[a]
    return qpos


def equality_rows(model: mujoco.MjModel, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """At rest at qpos: the closures' residuals (efc_pos), their Jacobian, and qfrc_bias (gravity)."""
    model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    J = data.efc_J.reshape(data.nefc, model.nv)[rows]
    return data.efc_pos[rows].copy(), J, data.qfrc_bias.copy()


def mujoco_gravity_torques(model: mujoco.MjModel, qpos: np.ndarray,
                           actuated: tuple[str, ...]) -> dict[str, float]:
    """g = Sᵀ τ + Jᵀ λ solved for τ, as Dynamics.gravity_torques does with Pinocchio's."""
    _, J, g = equality_rows(model, qpos)
    S = np.zeros((model.nv, len(actuated)))
    for k, name in enumerate(actuated):
        S[model.jnt_dofadr[model.joint(name).id], k] = 1.0
    A = np.hstack([S, J.T])
    x = np.linalg.lstsq(A, g, rcond=None)[0]
    assert np.linalg.norm(A @ x - g) < 1e-8 * max(1.0, float(np.linalg.norm(g)))
    return {name: float(x[k]) for k, name in enumerate(actuated)}


def assert_same_residual(model: mujoco.MjModel, dyn: Dynamics, q: np.ndarray) -> None:
    """MuJoCo's connects (site1 − site2) are Pinocchio's point constraints (parent − child),
    closed or not; both are in name order."""
    assert all(int(t) == mujoco.mjtEq.mjEQ_CONNECT for t in model.eq_type)
    residual, _ = dyn.residual(q)
    efc_pos, _, _ = equality_rows(model, mujoco_qpos(model, dyn, q))
    np.testing.assert_allclose(efc_pos[:residual.size], residual, atol=1e-12)


def assert_closes_as_pinocchio(model: mujoco.MjModel, dyn: Dynamics, q: np.ndarray) -> None:
    residual, _ = dyn.residual(q)
    assert np.linalg.norm(residual) < 1e-8  # Pinocchio's loops are closed at q
    qpos = mujoco_qpos(model, dyn, q)
    efc_pos, _, _ = equality_rows(model, qpos)
    assert np.abs(efc_pos).max() < 1e-8
    expected = dyn.gravity_torques(q)
    got = mujoco_gravity_torques(model, qpos, tuple(expected))
    assert got == pytest.approx(expected, abs=1e-7)


# -- Cassie ------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cassie(tmp_path_factory: pytest.TempPathFactory) -> tuple[mujoco.MjModel, Dynamics]:
    tmp = tmp_path_factory.mktemp("cassie")
    text = cassie_definition().replace("  test:\n", MJCF_EXPORT + "  test:\n", 1)
    write(tmp / "cassie.yml", text)
    result = compile_ok(tmp / "cassie.yml", tmp / "out")
    assert result.robot is not None
    return mujoco.MjModel.from_xml_path(str(tmp / "out/mjcf/cassie.xml")), build(result.robot)


def test_cassies_rods_are_four_connects_between_sites(cassie: tuple[mujoco.MjModel, Dynamics]) -> None:
    model, _ = cassie
    assert model.neq == 4
    assert list(model.eq_type) == [mujoco.mjtEq.mjEQ_CONNECT] * 4
    assert list(model.eq_objtype) == [mujoco.mjtObj.mjOBJ_SITE] * 4
    # The left pitch rod's ball joint sits 45 mm along the hip's z, not at its origin.
    site = model.site("left-pitch-rod-joint_child")
    assert model.body(int(model.site_bodyid[site.id])).name == "left-hip-pitch"
    np.testing.assert_allclose(site.pos, [0, 0, 0.045], atol=1e-12)


@pytest.mark.parametrize("pose", [
    {"right-knee-op": -0.5, "left-foot-op": -0.6},
    {"left-knee-op": -0.4, "right-knee-op": -0.3, "left-pitch-op": 0.2},
    {"left-knee-op": -0.6, "right-knee-op": -0.2, "right-pitch-op": 0.3, "left-roll-op": 0.1},
])
def test_cassies_loops_close_in_mujoco_where_pinocchio_closes_them(
        cassie: tuple[mujoco.MjModel, Dynamics], pose: dict[str, float]) -> None:
    model, dyn = cassie
    assert_closes_as_pinocchio(model, dyn, dyn.configuration(pose))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cassies_closures_are_pinocchios_at_any_configuration(
        cassie: tuple[mujoco.MjModel, Dynamics], seed: int) -> None:
    """Open or closed, the two sides of each rod are where Pinocchio puts them."""
    import pinocchio as pin

    model, dyn = cassie
    np.random.seed(seed)
    assert_same_residual(model, dyn, pin.randomConfiguration(dyn.model, -np.ones(dyn.model.nq),
                                                              np.ones(dyn.model.nq)))


def test_cassie_stays_closed_when_simulated(cassie: tuple[mujoco.MjModel, Dynamics]) -> None:
    """Released under gravity from a closed pose, the rods stay on their joints (within the
    millimetres MuJoCo's soft constraints sag under the legs' weight)."""
    model, dyn = cassie
    data = mujoco.MjData(model)
    data.qpos[:] = mujoco_qpos(model, dyn, dyn.configuration({"left-knee-op": -0.4, "right-knee-op": -0.3}))
    for _ in range(200):
        mujoco.mj_step(model, data)
    rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    assert np.abs(data.efc_pos[rows]).max() < 5e-3


# -- a four-bar whose closure sits off its child's origin -------------------------------------

def fourbar_sdf(loop: str) -> str:
    """The parallelogram of tests/checks/fourbar.py in SDF, the loop joint (`loop`: ball, or
    revolute about y) last, so it is the cut: it sits at the rocker's top, 1 m above the
    rocker's origin, and joins the coupler's far end."""
    def link(name: str, pose: str, com: str, mass: float, inertia: str) -> str:
        ixx, iyy, izz = inertia.split()
        return (f'<link name="{name}"><pose>{pose} 0 0 0</pose><inertial><pose>{com} 0 0 0</pose>'
                f"<mass>{mass}</mass><inertia><ixx>{ixx}</ixx><iyy>{iyy}</iyy><izz>{izz}</izz>"
                "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>\n")

    def joint(name: str, kind: str, parent: str, child: str, pose: str = "0 0 0") -> str:
        axis = "<axis><xyz>0 1 0</xyz></axis>" if kind == "revolute" else ""
        return (f'<joint name="{name}" type="{kind}"><pose>{pose} 0 0 0</pose><parent>{parent}</parent>'
                f"<child>{child}</child>{axis}</joint>\n")

    return ('<?xml version="1.0"?>\n<sdf version="1.9"><model name="fourbar">\n'
            + link("base", "0 0 0", "1 0 0", 5, "0.1 0.1 0.1")
            + link("crank", "0 0 0", "0 0 0.5", 1, "0.084 0.084 0.001")
            + link("coupler", "0 0 1", "1 0 0", 2, "0.001 0.67 0.67")
            + link("rocker", "2 0 0", "0 0 0.5", 3, "0.25 0.25 0.001")
            + joint("fix", "fixed", "world", "base")
            + joint("crank_joint", "revolute", "base", "crank")
            + joint("coupler_joint", "revolute", "crank", "coupler")
            + joint("rocker_joint", "revolute", "base", "rocker")
            + joint("loop", loop, "coupler", "rocker", "0 0 1")
            + "</model></sdf>\n")


def fourbar(tmp_path: Path, loop: str) -> Robot:
    path = write(tmp_path / "fourbar.sdf", fourbar_sdf(loop))
    robot = sdf_reader.read(path, Diags())
    assert robot is not None and set(robot.cut_joints) == {"loop"}
    assert robot.cut_joints["loop"].annotations["joint_origin"]["xyz"] == pytest.approx([0, 0, 1])
    return replace(robot, motors={"crank": Motor(name="crank", joint="crank_joint")})


@pytest.mark.parametrize("loop", ["ball", "revolute"])
@pytest.mark.parametrize("theta", [0.0, 0.4, -1.1])
def test_a_fourbar_closes_in_mujoco_where_pinocchio_closes_it(tmp_path: Path, loop: str,
                                                              theta: float) -> None:
    robot = fourbar(tmp_path, loop)
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str))
    dyn = build(robot)
    q = dyn.configuration({"crank_joint": theta})
    # the parallelogram: the coupler turns back by θ, the rocker turns by θ
    qpos = mujoco_qpos(model, dyn, q)
    assert np.angle(np.exp(1j * (qpos - [theta, -theta, theta]))) == pytest.approx(0.0, abs=1e-9)
    assert_closes_as_pinocchio(model, dyn, q)
    if loop == "ball":
        assert_same_residual(model, dyn, np.array([np.cos(theta), np.sin(theta), 1.0, 0.0, 0.0, 1.0]))
    # τ = -g sin θ (m_crank/2 + m_coupler + m_rocker/2), as in tests/checks/test_loops.py
    got = mujoco_gravity_torques(model, qpos, ("crank_joint",))
    assert got["crank_joint"] == pytest.approx(-9.81 * np.sin(theta) * (0.5 + 2 + 1.5), abs=1e-7)


def test_a_revolute_closure_with_an_axis_is_a_hinge(tmp_path: Path) -> None:
    """Two connects, the second one AXIS_POINT along the axis (y) on both sides; that it is
    the axis the loop turns about shows in the closed four-bar test above (its residual)."""
    sink = Diags()
    text = mjcf.to_string(fourbar(tmp_path, "revolute"), str, sink)
    assert sink.diagnostics == []  # nothing left out: the hinge is all there
    model = mujoco.MjModel.from_xml_string(text)
    assert [model.eq(i).name for i in range(model.neq)] == ["loop", "loop_axis"]
    np.testing.assert_allclose(model.site("loop_child_axis").pos, [0, mjcf.AXIS_POINT, 1], atol=1e-12)
    np.testing.assert_allclose(model.site("loop_parent_axis").pos, [2, mjcf.AXIS_POINT, 0], atol=1e-12)


def test_a_translational_closure_is_named_in_the_warning(tmp_path: Path) -> None:
    robot = fourbar(tmp_path, "ball")
    robot = replace(robot, cut_joints={"loop": replace(robot.cut_joints["loop"], type="prismatic")})
    sink = Diags()
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str, sink))
    assert model.neq == 0 and model.nsite == 0
    warning = sink.take("W0500", Severity.WARNING).message
    assert warning.endswith("prismatic cut joint 'loop' (MJCF has no equality for it)")


def test_the_compiled_fourbar_definition_closes_in_mujoco(tmp_path: Path) -> None:
    """From the model definition (tests/checks/fourbar.py: a revolute cut joint without an
    axis, so a ball closure) to out/mjcf/fourbar.xml."""
    write(tmp_path / "fourbar.urdf", FOURBAR_URDF)
    write(tmp_path / "fourbar.yml", FOURBAR_DEFINITION + MJCF_EXPORT)
    result = compile_ok(tmp_path / "fourbar.yml", tmp_path / "out")
    assert result.robot is not None
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out/mjcf/fourbar.xml"))
    dyn = build(result.robot)
    assert dyn.actuated == ("crank_joint",)
    for theta in (0.3, -0.9):
        assert_closes_as_pinocchio(model, dyn, dyn.configuration({"crank_joint": theta}))


def test_a_closure_open_at_q0_closes_where_pinocchio_closes_it(tmp_path: Path) -> None:
    """A cut joint whose origin does not agree with the tree at q = 0 (as a SMURF may give
    it): the coupler's end is 1.8 m out, the rocker's top 2 m, so the loop is open at q = 0.
    With body1/anchor MuJoCo would take the open pose as the closed one; the sites close it
    where Pinocchio does."""
    robot = fourbar(tmp_path, "ball")
    cut = replace(robot.cut_joints["loop"], origin=Pose((1.8, 0.0, -1.0), (0.0, 0.0, 0.0)))
    robot = replace(robot, cut_joints={"loop": cut})
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str))
    dyn = build(robot)
    q0 = np.array([1.0, 0.0, 1.0, 0.0, 1.0, 0.0])
    assert_same_residual(model, dyn, q0)
    assert np.abs(equality_rows(model, model.qpos0)[0]).max() == pytest.approx(0.2)
    q = dyn.configuration({"crank_joint": 0.5})
    assert_closes_as_pinocchio(model, dyn, q)


def test_a_fixed_closure_is_a_weld_of_the_two_frames(tmp_path: Path) -> None:
    """A fixed cut joint whose origin is the coupler-to-rocker pose at θ = 0.5 (not at q = 0):
    the weld holds position and orientation exactly where Pinocchio's 6D constraint does."""
    from mpc.ir.kinematics import matrix_pose

    ball = fourbar(tmp_path, "ball")
    q = build(ball).configuration({"crank_joint": 0.5})
    X = build(ball).link_placements(q)
    cut = replace(ball.cut_joints["loop"], type="fixed",
                  origin=matrix_pose(np.linalg.inv(X["coupler"]) @ X["rocker"]))
    robot = replace(ball, cut_joints={"loop": cut})
    dyn = build(robot)
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str))
    assert list(model.eq_type) == [mujoco.mjtEq.mjEQ_WELD]
    assert np.linalg.norm(dyn.residual(q)[0]) < 1e-12
    assert np.abs(equality_rows(model, mujoco_qpos(model, dyn, q))[0]).max() < 1e-12
    open_at_q0 = equality_rows(model, model.qpos0)[0]
    assert np.abs(open_at_q0[3:]).max() > 0.1  # the rotation part: the coupler is turned by 0.5
