"""physical_validity on real models: the known bad links of example-robot-data are flagged,
clean models give nothing, and `- physical_validity: error` turns findings into a failure."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.backends.urdf_reader import read
from mpc.checks.validity import findings, inertia_problem
from mpc.compiler.diagnostics import Severity, Sink
from mpc.ir.robot import Inertia
from tests.checks.helpers import definition, result, run, write
from tests.conftest import ERD


def flagged(path: Path) -> dict[str, str]:
    robot = read(path, Sink())
    assert robot is not None
    return dict(findings(robot, 0.003))


def test_talos_links_with_mass_but_no_inertia_are_flagged() -> None:
    """talos_full_v2: three sensor and tool frames have a mass and a zero inertia tensor."""
    found = flagged(ERD / "talos_data/robots/talos_full_v2.urdf")
    assert set(found) == {"rgbd_optical_frame", "wrist_left_ft_tool_link", "wrist_right_ft_tool_link"}
    assert found["wrist_left_ft_tool_link"] == \
        "inertia is not positive definite (principal moments (0, 0, 0))"


def test_inertias_violating_the_triangle_inequality_are_flagged() -> None:
    """The allegro hands' link_3.0, link_7.0, link_11.0 and link_15.0 (their tips) have
    principal moments A + B < C; pr2's stereo mount too."""
    hand = flagged(ERD / "allegro_hand_description/urdf/allegro_right_hand.urdf")
    triangle = {link for link, p in hand.items() if "triangle inequality" in p}
    assert triangle == {"link_3.0", "link_7.0", "link_11.0", "link_15.0"}
    pr2 = flagged(ERD / "pr2_description/urdf/pr2.urdf")
    assert "violate the triangle inequality" in pr2["double_stereo_link"]


@pytest.mark.parametrize("model", ["solo_description/robots/solo12.urdf", "z1_description/urdf/z1.urdf",
                                   "kinova_description/robots/kinova.urdf",
                                   "double_pendulum_description/urdf/double_pendulum.urdf"])
def test_clean_models_give_no_finding(model: str) -> None:
    assert flagged(ERD / model) == {}


def test_the_triangle_tolerance_is_relative_to_the_largest_moment() -> None:
    exact = Inertia(ixx=1.0, ixy=0.0, ixz=0.0, iyy=1.0, iyz=0.0, izz=2.0)  # a flat plate: A + B = C
    assert inertia_problem(exact) == ""
    tiny = Inertia(ixx=1e-9, ixy=0.0, ixz=0.0, iyy=1e-9, iyz=0.0, izz=2.0000001e-9)  # 5e-8 relative
    assert inertia_problem(tiny) == ""
    bad = Inertia(ixx=1e-9, ixy=0.0, ixz=0.0, iyy=1e-9, iyz=0.0, izz=2.1e-9)
    assert "violate the triangle inequality" in inertia_problem(bad)


def test_findings_are_warnings_unless_configured_as_errors(tmp_path: Path) -> None:
    talos = ERD / "talos_data/robots/talos_full_v2.urdf"
    write(tmp_path / "w.yml", definition(talos, "talos", "      - compare_amount_joints\n"))
    sink = Sink()
    protocol = run(tmp_path / "w.yml", tmp_path / "w", tmp_path / "work", sink)
    validity = result(protocol, "physical_validity")
    assert (validity.status, validity.figure) == ("passed", 3.0)
    warnings = [d for d in sink.diagnostics if d.code == "W0701"]
    assert [d.severity for d in warnings] == [Severity.WARNING] * 3
    assert warnings[0].span.file.endswith("talos.urdf")  # the written model, at the link
    write(tmp_path / "e.yml", definition(talos, "talos", "      - physical_validity: error\n"))
    protocol = run(tmp_path / "e.yml", tmp_path / "e", tmp_path / "work")
    validity = result(protocol, "physical_validity")
    assert validity.status == "failed" and protocol.failed
    assert validity.reason.startswith("link 'rgbd_optical_frame' inertia is not positive definite")
    assert [r.name for r in protocol.results].count("physical_validity") == 1  # listed: not run twice


def test_a_moving_link_without_mass_and_a_com_outside_its_shapes(tmp_path: Path) -> None:
    from tests.checks.fourbar import FOURBAR_URDF

    urdf = FOURBAR_URDF.replace('<origin xyz="0 0 0.5"/><mass value="3"/>',
                                '<origin xyz="0 0 1.5"/><mass value="3"/>')
    urdf = urdf.replace('<origin xyz="1 0 0"/><mass value="2"/>', '<origin xyz="1 0 0"/><mass value="0"/>')
    write(tmp_path / "f.urdf", urdf)
    robot = read(tmp_path / "f.urdf", Sink())
    assert robot is not None
    found = findings(robot, 0.003)
    assert found[:2] == [("coupler", "moves with joint 'coupler_joint' but neither it nor a link beyond "
                                     "it has mass"),
                         ("coupler", "has collision shapes but no mass")]
    assert found[2][0] == "rocker"
    assert found[2][1].startswith("COM (0, 0, 1.5) m lies 0.5 m outside the collision bounding box")
    assert len(found) == 3


def test_a_massless_link_between_joints_of_a_3_dof_joint_is_not_a_finding() -> None:
    """example-robot-data's human: each ankle, wrist, hip and shoulder is three revolute joints
    with massless `…_virtual` links between them; the mass is beyond them, so they are fine."""
    assert flagged(ERD / "human_description/robots/human.urdf") == {}
