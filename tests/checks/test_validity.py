"""physical_validity on real models: the known bad links of example-robot-data are flagged,
clean models give nothing, and `- physical_validity: error` turns findings into a failure."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.backends.urdf_reader import read
from mpc.checks.validity import findings, inertia_problem
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.robot import Inertia
from tests.checks.helpers import definition, result, run, write
from tests.conftest import ERD


def flagged(path: Path) -> dict[str, str]:
    """The W0701 findings (possibility; the plausibility ones are tested below)."""
    robot = read(path, Sink())
    assert robot is not None
    return {link: problem for link, code, problem in findings(robot, 0.003) if code == "W0701"}


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
    assert (validity.status, validity.figure) == ("passed", 6.0)  # and three implausible densities
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
    found = [(link, problem) for link, code, problem in findings(robot, 0.003) if code == "W0701"]
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


# -- plausibility: the declared mass properties against the collision solid ------------------

CUBE = """
<robot name="cube">
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="body"/><axis xyz="0 0 1"/>
    <limit effort="1" velocity="1" lower="-1" upper="1"/></joint>
  <link name="body">
    <inertial><origin xyz="COM"/><mass value="MASS"/>
      <inertia ixx="I" ixy="0" ixz="0" iyy="I" iyz="0" izz="I"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>
"""


def _cube(tmp_path: Path, com: str = "0 0 0", mass: float = 2.0, inertia: float | None = None) -> Path:
    """A 10 cm cube of `mass` (2 kg: 2000 kg/m³) with its own inertia unless told otherwise."""
    i = inertia if inertia is not None else mass * 0.01 / 6
    return write(tmp_path / "cube.urdf", CUBE.replace("COM", com).replace("MASS", repr(mass))
                 .replace('"I"', f'"{i!r}"'))


def _found(path: Path, **settings) -> list[tuple[str, str, str]]:
    robot = read(path, Sink())
    assert robot is not None
    return findings(robot, 0.003, **settings)


def test_a_plausible_link_gives_nothing(tmp_path: Path) -> None:
    assert _found(_cube(tmp_path)) == []


def test_a_com_1_m_outside_its_link_is_flagged_with_its_figures(tmp_path: Path) -> None:
    assert _found(_cube(tmp_path, com="1.05 0 0")) == [
        ("body", "W0701", "COM (1.05, 0, 0) m lies 1 m outside the collision bounding box "
                          "(-0.05, -0.05, -0.05)…(0.05, 0.05, 0.05) m")]


def test_an_implausible_density_is_flagged_within_a_configurable_range(tmp_path: Path) -> None:
    """50 kg in a litre: 50 g/cm³, what a unit mistake in CAD export gives."""
    cube = _cube(tmp_path, mass=50.0)
    assert _found(cube) == [("body", "W0710", "implied density 5e+04 kg/m³ (mass 50 kg in 0.001 m³ of "
                                              "collision solid) lies outside 100–25000 kg/m³")]
    assert _found(cube, density=(100.0, 60000.0)) == []


def test_principal_moments_far_from_the_geometrys_are_flagged(tmp_path: Path) -> None:
    """The cube's moments are m·a²/6 = 0.00333 kg·m²; twenty times that is flagged at the
    default factor (10), not with a factor of 30."""
    cube = _cube(tmp_path, inertia=20 * 2.0 * 0.01 / 6)
    assert _found(cube) == [("body", "W0711", "principal moments (0.06667, 0.06667, 0.06667) kg·m² differ "
                                              "from the collision solid's (0.003333, 0.003333, 0.003333) "
                                              "kg·m² at its mass by up to a factor of 20 (more than 10)")]
    assert _found(cube, factor=30.0) == []


def test_plausibility_on_talos_and_ur5() -> None:
    """What the plausibility check finds on real models (they are in the report of issue 23):
    TALOS's camera and force-torque tool frames weigh 10 g and 1 g in 222 and 19 cm³ (densities
    45 and 52 kg/m³); UR5's wrist inertias are 142 to 263 times what their collision meshes
    give at their masses (ur_description's well-known cylinder inertias). With a range and a
    factor that accept these, both are silent."""
    def plausibility(path: Path, **settings) -> dict[str, str]:
        return {link: code for link, code, _ in _found(path, **settings) if code != "W0701"}

    talos, ur5 = ERD / "talos_data/robots/talos_full_v2.urdf", ERD / "ur_description/urdf/ur5_robot.urdf"
    assert plausibility(talos) == {"rgbd_link": "W0710", "wrist_left_ft_tool_link": "W0710",
                                   "wrist_right_ft_tool_link": "W0710"}
    assert plausibility(ur5) == {"wrist_1_link": "W0711", "wrist_2_link": "W0711", "wrist_3_link": "W0711"}
    assert plausibility(talos, density=(40.0, 25000.0)) == {}
    assert plausibility(ur5, factor=300.0) == {}


def test_the_protocol_lists_the_figures_and_the_settings_come_from_the_definition(tmp_path: Path) -> None:
    cube = _cube(tmp_path, mass=50.0)
    tests = "      - physical_validity: {density: [100, 60000]}\n"
    write(tmp_path / "w.yml", definition(cube, "cube", tests))
    sink = Sink()
    validity = result(run(tmp_path / "w.yml", tmp_path / "w", tmp_path / "work", sink), "physical_validity")
    assert (validity.status, validity.figure) == ("passed", 0.0)
    write(tmp_path / "e.yml", definition(cube, "cube", "      - physical_validity:\n"
                                                       "          severity: error\n"
                                                       "          inertia_factor: 2\n"))
    protocol = run(tmp_path / "e.yml", tmp_path / "e", tmp_path / "work")
    validity = result(protocol, "physical_validity")
    assert validity.status == "failed"
    assert validity.details == ("body: implied density 5e+04 kg/m³ (mass 50 kg in 0.001 m³ of collision "
                                "solid) lies outside 100–25000 kg/m³",)
    assert "body: implied density 5e+04 kg/m³" in protocol.markdown()
