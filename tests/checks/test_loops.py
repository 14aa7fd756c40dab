"""Closed loops: cut joints become Pinocchio constraints, so the torques are those of the
actuated joints of the closed mechanism (a four-bar against its closed form; Cassie's legs
from example-robot-data against the principle of virtual work)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import scipy.linalg

from mpc.checks.models import load_built
from tests.checks.fourbar import FOURBAR_DEFINITION, FOURBAR_URDF
from tests.checks.helpers import compile_ok, failing, result, run, statuses, write
from tests.conftest import ERD

G = 9.81
SDF_WITH_LOOPS = "    - type: sdf\n      mesh_format: input_type\n      include_cut_joints: true\n"


def fourbar(tmp_path: Path, tests: str, rocker_mass: float = 3.0) -> str:
    urdf = FOURBAR_URDF.replace('<mass value="3"/>', f'<mass value="{rocker_mass}"/>')
    write(tmp_path / "fourbar.urdf", urdf)
    return FOURBAR_DEFINITION + SDF_WITH_LOOPS + "  test:\n" + tests


def expected_crank_torque(theta: float, rocker: float = 3.0) -> float:
    """τ = -g sin θ (m_crank/2 + m_coupler + m_rocker/2) for the parallelogram (see fourbar.py)."""
    return -G * np.sin(theta) * (1.0 / 2 + 2.0 + rocker / 2)


@pytest.mark.parametrize("theta", [0.3, -0.7, 1.1])
def test_fourbar_crank_torque_is_that_of_the_closed_mechanism(tmp_path: Path, theta: float) -> None:
    write(tmp_path / "fourbar.yml", fourbar(tmp_path, "    tests: []\n"))
    result_ = compile_ok(tmp_path / "fourbar.yml", tmp_path / "out")
    model, problem = load_built(result_.program, tmp_path / "out", result_.robot)
    assert model is not None, problem
    dyn = model.dynamics()
    assert dyn.actuated == ("crank_joint",)
    [loop] = dyn.constraints
    assert loop.name == "loop" and loop.type == pin.ContactType.CONTACT_3D
    q = dyn.configuration({"crank_joint": theta})
    # the parallelogram: the coupler turns back by θ, the rocker turns by θ
    wrapped = np.angle(np.exp(1j * (q - [theta, -theta, theta])))  # one turn is the same pose
    assert wrapped == pytest.approx(0.0, abs=1e-9)
    tau = dyn.gravity_torques(q)
    assert tau["crank_joint"] == pytest.approx(expected_crank_torque(theta), abs=1e-8)
    # The tree alone (the loop cut open) would hold only the crank and the coupler.
    tree = pin.computeGeneralizedGravity(dyn.model, dyn.data, q)[0]
    assert abs(tree - tau["crank_joint"]) > 1.0


def test_fourbar_compare_torques_sees_the_rocker_through_the_loop(tmp_path: Path) -> None:
    """The rocker hangs on the base, not on the crank: only the closed loop makes its mass
    load the crank, by Δτ = g sin θ Δm / 2."""
    tests = "    compare_model:\n      path: ref\n      model_in_repo: sdf/fourbar.sdf\n    tests:\n" \
            "      - hyrodynChecks:\n          - load_in_hyrodyn\n" \
            "          - move_hyrodyn_model: {crank_joint: 0.5}\n" \
            "          - compare_torques\n"
    write(tmp_path / "ref.yml", fourbar(tmp_path, "    tests: []\n", rocker_mass=3.2))
    compile_ok(tmp_path / "ref.yml", tmp_path / "ref")
    write(tmp_path / "fourbar.yml", fourbar(tmp_path, tests))
    protocol = run(tmp_path / "fourbar.yml", tmp_path / "out", tmp_path / "work")
    torques = result(protocol, "compare_torques")
    assert torques.status == "failed"
    assert torques.figure == pytest.approx(G * np.sin(0.5) * 0.2 / 2, abs=1e-8)
    assert "with 1 loop closure at crank_joint = 0.5" in torques.reason
    assert result(protocol, "load_in_hyrodyn").reason == "Pinocchio: 3 joints, 3 coordinates, 1 loop closure"
    assert failing(protocol) == {"compare_torques"}


def test_fourbar_against_itself_passes(tmp_path: Path) -> None:
    tests = "    compare_model:\n      path: ref\n      model_in_repo: sdf/fourbar.sdf\n    tests:\n" \
            "      - hyrodynChecks: [load_in_hyrodyn, {move_hyrodyn_model: 0.8}, compare_torques, " \
            "compare_com]\n"
    write(tmp_path / "fourbar.yml", fourbar(tmp_path, tests))
    compile_ok(tmp_path / "fourbar.yml", tmp_path / "ref")
    protocol = run(tmp_path / "fourbar.yml", tmp_path / "out", tmp_path / "work")
    assert set(statuses(protocol).values()) == {"passed"}, protocol.markdown()


CASSIE_ACTUATED = ("roll-op", "yaw-op", "pitch-op", "knee-op", "foot-op", "knee-shin-joint")


def cassie_definition() -> str:
    """cassie_v2 (SDF, its four rods closed by ball joints), with motors on the five actuated
    joints of each leg and on the knee spring (stiff: it carries the shin's load)."""
    joints = "".join(f"    {side}-{j}:\n      active: true\n"
                     for side in ("left", "right") for j in CASSIE_ACTUATED)
    return f"""\
model:
  robotname: cassie
  modelname: cassie-model
  input_models:
    base:
      basefile: "{ERD / 'cassie_description/robots/cassie_v2.sdf'}"
  assemble:
    model: base
  joints:
    $all: true
    $default:  # URDF needs effort and velocity limits, which the SDF does not give
      eff: 100
      vel: 10
{joints}  export_config:
    - type: urdf
      mesh_format: input_type
{SDF_WITH_LOOPS}  test:
    compare_model:  # the released model, with its rods
      path: "{ERD / 'cassie_description/robots/cassie_v2.sdf'}"
    tests:
      - hyrodynChecks:
          - load_in_hyrodyn
          - move_hyrodyn_model: {{left-knee-op: -0.4, right-knee-op: -0.3, left-pitch-op: 0.2}}
          - compare_torques
          - compare_com
          - compare_link_positions
"""


def test_cassie_torques_satisfy_virtual_work_with_the_loops_closed(tmp_path: Path) -> None:
    write(tmp_path / "cassie.yml", cassie_definition())
    result_ = compile_ok(tmp_path / "cassie.yml", tmp_path / "out")
    model, problem = load_built(result_.program, tmp_path / "out", result_.robot)
    assert model is not None, problem
    dyn = model.dynamics()
    assert len(dyn.constraints) == 4
    assert len(dyn.actuated) == 12
    q = dyn.configuration({"left-knee-op": -0.4, "right-knee-op": -0.3, "left-pitch-op": 0.2})
    residual, J = dyn.residual(q)
    assert np.linalg.norm(residual) < 1e-10  # the rods are closed
    tau = dyn.gravity_torques(q)
    g = pin.computeGeneralizedGravity(dyn.model, dyn.data, q)
    # Every motion the closed mechanism allows does the same work by the actuated torques
    # as gravity does: τ_a · v_a = g · v for v in the null space of the constraint Jacobian.
    S = np.zeros(dyn.model.nv)
    for name, value in tau.items():
        S[dyn.model.idx_vs[dyn.model.getJointId(name)]] = value
    for v in scipy.linalg.null_space(J).T:
        assert S @ v == pytest.approx(g @ v, abs=1e-8)
    # and it is not the tree's answer: the rods carry load
    tree = {n: g[dyn.model.idx_vs[dyn.model.getJointId(n)]] for n in tau}
    assert max(abs(tau[n] - tree[n]) for n in tau) > 0.05


def test_cassie_against_itself_passes_with_its_loops(tmp_path: Path) -> None:
    write(tmp_path / "cassie.yml", cassie_definition())
    protocol = run(tmp_path / "cassie.yml", tmp_path / "out", tmp_path / "work")
    s = statuses(protocol)
    dynamics = ("load_in_hyrodyn", "move_hyrodyn_model", "compare_torques", "compare_com",
                "compare_link_positions")
    assert all(s[n] == "passed" for n in dynamics), protocol.markdown()
    assert result(protocol, "load_in_hyrodyn").reason.endswith("4 loop closures")
    assert "12 joint torques with 4 loop closures" in result(protocol, "compare_torques").reason


def test_an_underactuated_loop_fails_with_the_reason(tmp_path: Path) -> None:
    """Without the knee springs, Cassie's shins have a motion no motor holds."""
    text = cassie_definition().replace("    left-knee-shin-joint:\n      active: true\n", "") \
        .replace("    right-knee-shin-joint:\n      active: true\n", "")
    write(tmp_path / "cassie.yml", text)
    protocol = run(tmp_path / "cassie.yml", tmp_path / "out", tmp_path / "work")
    torques = result(protocol, "compare_torques")
    assert torques.status == "failed"
    assert "cannot hold this configuration against gravity" in torques.reason


def test_without_motors_the_submechanisms_active_joints_are_driven(tmp_path: Path) -> None:
    from dataclasses import replace

    from mpc.checks.dynamics_model import build
    from mpc.ir.extras import Submechanism

    write(tmp_path / "fourbar.yml", fourbar(tmp_path, "    tests: []\n"))
    built = compile_ok(tmp_path / "fourbar.yml", tmp_path / "out")
    model, _ = load_built(built.program, tmp_path / "out", built.robot)
    assert model is not None
    robot = replace(model.robot, motors={}, submechanisms=(
        Submechanism(name="fourbar", definition={"jointnames_active": ["crank_joint"]}),))
    dyn = build(robot)
    assert dyn.actuated == ("crank_joint",)
    q = dyn.configuration({"crank_joint": 0.3})
    assert dyn.gravity_torques(q)["crank_joint"] == pytest.approx(expected_crank_torque(0.3), abs=1e-8)


@pytest.mark.parametrize("present", [True, False])
def test_the_compare_models_submechanisms_file_is_read(tmp_path: Path, present: bool) -> None:
    tests = "    compare_model:\n      path: ref\n      model_in_repo: sdf/fourbar.sdf\n" \
            "      submechanisms_in_repo: fourbar_submechanisms.yml\n    tests:\n" \
            "      - hyrodynChecks: [load_in_hyrodyn, compare_torques]\n"
    write(tmp_path / "fourbar.yml", fourbar(tmp_path, tests))
    compile_ok(tmp_path / "fourbar.yml", tmp_path / "ref")
    if present:
        write(tmp_path / "ref/fourbar_submechanisms.yml",
              "submechanisms:\n  - name: fourbar\n    jointnames_active: [crank_joint]\n")
    protocol = run(tmp_path / "fourbar.yml", tmp_path / "out", tmp_path / "work")
    if present:  # and file_consistency notices that the new output lacks it
        assert failing(protocol) == {"file_consistency"}, protocol.markdown()
    else:
        assert result(protocol, "compare_torques").reason == "the compare model cannot be loaded: " \
            "cannot read submechanisms_in_repo 'fourbar_submechanisms.yml'"


def test_cassie_against_its_own_compiled_sdf(tmp_path: Path) -> None:
    """The compiled SDF keeps where each rod's ball joint sits, so the loops read back the same."""
    released = f"      path: \"{ERD / 'cassie_description/robots/cassie_v2.sdf'}\"\n"
    text = cassie_definition().replace(released, "      path: ref\n      model_in_repo: sdf/cassie.sdf\n")
    assert "model_in_repo: sdf/cassie.sdf" in text
    write(tmp_path / "cassie.yml", text)
    compile_ok(tmp_path / "cassie.yml", tmp_path / "ref")
    protocol = run(tmp_path / "cassie.yml", tmp_path / "out", tmp_path / "work")
    assert set(statuses(protocol).values()) == {"passed"}, protocol.markdown()
    assert result(protocol, "compare_link_positions").figure < 1e-6


def test_a_configuration_where_the_loop_cannot_close_fails_and_keeps_the_previous_one(tmp_path: Path) -> None:
    """Crank and rocker both driven, at +0.5 and -0.5 rad: their tips are 1.04 m apart and the
    2 m coupler cannot join them. move_hyrodyn_model fails with the residual; the checks after
    it run at the configuration before it (both at 0.3), where the loop closes."""
    definition = fourbar(tmp_path, "    tests:\n      - hyrodynChecks:\n"
                         "          - move_hyrodyn_model: {crank_joint: 0.3, rocker_joint: 0.3}\n"
                         "          - move_hyrodyn_model: {crank_joint: 0.5, rocker_joint: -0.5}\n"
                         "          - symmetry_check: {links: [coupler, rocker_tip], plane: [1, 0, 0]}\n")
    write(tmp_path / "fourbar.yml", definition.replace("    crank_joint:\n      active: true\n",
                                                       "    crank_joint:\n      active: true\n"
                                                       "    rocker_joint:\n      active: true\n"))
    protocol = run(tmp_path / "fourbar.yml", tmp_path / "out", tmp_path / "work")
    s = statuses(protocol)
    assert (s["move_hyrodyn_model"], s["move_hyrodyn_model 2"]) == ("passed", "failed")
    reason = result(protocol, "move_hyrodyn_model 2").reason
    assert reason.startswith("the compiled model: the loops do not close at this configuration (residual ")
    assert reason.endswith("): the actuated joints' values are not reachable")
    # the coupler hangs on the crank's tip: (sin 0.3, 0, cos 0.3), mirrored in x
    assert "'coupler' mirrored at (-0.2955, 0, 0.9553) m" in result(protocol, "symmetry_check").reason
