"""Lowering `test` into the IR's TestPlan: merged tolerances, checked arguments, the compare
model, test data; the IR text dump reads back the same plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.compiler.driver import Options
from mpc.compiler.front_end import load_program
from mpc.ir.program import CompareTarget, ModelTest, Tolerances
from mpc.ir.text import dump, parse
from tests.conftest import Diags, definition, write
from tests.fixtures import ARM_URDF, tetra_stl


def program(tmp_path: Path, test: str, diags: Diags):
    write(tmp_path / "arm.urdf", ARM_URDF)
    tetra_stl(tmp_path / "meshes" / "tetra.stl")
    write(tmp_path / "arm.yml", definition("arm.urdf") + "  test:\n" + test)
    return load_program(tmp_path / "arm.yml", diags, Options())


def test_tolerances_merge_with_the_defaults(tmp_path: Path, diags: Diags) -> None:
    p = program(tmp_path, "    tolerances:\n      mass: 2*0.05\n    tests: [compare_link_masses]\n", diags)
    assert p.test.tolerances == Tolerances(default=0.01, mass=0.1, rad=0.03, distance=0.003)


def test_every_argument_form_and_the_ir_round_trip(tmp_path: Path, diags: Diags) -> None:
    write(tmp_path / "test_data.yml", "test_data:\n  expected_mass: 3.5\n")
    p = program(tmp_path, """\
    compare_model:
      git: released.git
      commit: "82b92a86"
      model_in_repo: urdf/arm.urdf
      ignore_failing_tests_for: "82b92a86"
    tests:
      - total_mass
      - symmetry_check_masses: [upper, lower]
      - physical_validity: error
      - hyrodynChecks:
          - move_hyrodyn_model: ["deg", 30]
          - move_hyrodyn_model: [0.1, 0.2]
          - move_hyrodyn_model: {shoulder: pi/4}
          - symmetry_check: {links: [upper, lower], plane: [1, 0, 0]}
          - compare_link_positions
""", diags)
    plan = p.test
    assert plan.expected_mass == 3.5
    assert plan.compare == CompareTarget(span=plan.compare.span, git=str(tmp_path / "released.git"),
                                         commit="82b92a86", model_in_repo="urdf/arm.urdf",
                                         ignore_failing_tests_for="82b92a86")
    tests = [(t.name, t.dynamics) for t in plan.tests]
    assert tests == [("total_mass", False), ("symmetry_check_masses", False), ("physical_validity", False),
                     *[("move_hyrodyn_model", True)] * 3, ("symmetry_check", True),
                     ("compare_link_positions", True)]
    t = plan.tests
    assert t[1].links == ("upper", "lower") and t[2].as_error
    assert t[3].angle == pytest.approx(0.5235987755982988)
    assert (t[4].angles, t[5].joint_angles) == ((0.1, 0.2), {"shoulder": pytest.approx(0.7853981633974483)})
    assert t[6].plane == (1.0, 0.0, 0.0)
    assert (t[0].span.line, t[0].span.col) == (19, 9)
    sink = Diags()
    back = parse(dump(p), "arm.ir", sink)
    assert back is not None and back.test == p.test
    assert isinstance(back.test.tests[0], ModelTest)


@pytest.mark.parametrize(("test", "code", "message"), [
    ("    tests:\n      - compare_link_masses: 3\n", "E0703", "test 'compare_link_masses' takes no argument"),
    ("    tests:\n      - symmetry_check_masses: [a]\n", "E0703",
     "test 'symmetry_check_masses' needs two link names [left, right], got ['a']"),
    ("    tests:\n      - hyrodynChecks: [move_hyrodyn_model]\n", "E0703",
     "test 'move_hyrodyn_model' needs an argument: a joint value, a list of values or a mapping "
     "{joint: value}"),
    ("    tests:\n      - physical_validity: loud\n", "E0703",
     "test 'physical_validity': the argument is 'error' (findings fail the test) or 'warning', got 'loud'"),
    ("    tests:\n      - physical_validity: {severity: loud}\n", "E0703",
     "test 'physical_validity': the argument is 'error' (findings fail the test) or 'warning', got 'loud'"),
    ("    tests:\n      - physical_validity: {density: [100]}\n", "E0703",
     "test 'physical_validity': 'density' is the range of plausible densities [min, max] in kg/m³, "
     "0 ≤ min < max, e.g. [100, 25000]"),
    ("    tests:\n      - physical_validity: {density: [500, 100]}\n", "E0703",
     "test 'physical_validity': 'density' is the range of plausible densities [min, max] in kg/m³, "
     "0 ≤ min < max, e.g. [100, 25000]"),
    ("    tests:\n      - physical_validity: {inertia_factor: 0.5}\n", "E0703",
     "test 'physical_validity': 'inertia_factor' is at least 1, got 0.5"),
    ("    tests:\n      - physical_validity: {densty: [1, 2]}\n", "E0703",
     "test 'physical_validity': unknown key 'densty' (it takes 'severity', 'density' and 'inertia_factor')"),
    ("    tests:\n      - hyrodynChecks: [{symmetry_check: {links: [a, b], plane: [0, 0, 0]}}]\n", "E0703",
     "test 'symmetry_check': 'plane' is the normal of the mirror plane, three numbers not all zero, "
     "e.g. [0, 1, 0]"),
    ("    tolerances: {distance: -1}\n", "E0701", "tolerance 'distance' must not be negative, got -1"),
    ("    tests:\n      - symmetry_check_masses: [upper, upper]\n", "E0703",
     "test 'symmetry_check_masses' compares two different links; both are 'upper'"),
    ("    tests:\n      - total_mass: -5\n", "E0703",
     "test 'total_mass': the expected mass must not be negative, got -5"),
    ("    compare_model: {git: a.git, path: b}\n", "E0701",
     "compare_model needs either 'git' (a repository) or 'path' (a folder or model file), not both"),
    ("    compare_model: {path: b, commit: '1234'}\n", "E0701",
     "'commit' needs a 'git' compare model; 'path' names a folder as it is"),
    ("    test_data_file: nothing.yml\n", "E0702", "test_data_file 'nothing.yml' does not exist"),
    ("    compare_model: {path: b, ignore_failing_tests_for: '82b92a86'}\n", "E0701",
     "'ignore_failing_tests_for' names a commit of a 'git' compare model; a 'path' has no commits"),
    ("    compare_model: {git: a.git, ignore_failing_tests_for: '8'}\n", "E0701",
     "'ignore_failing_tests_for' is a commit of the compare repository: 4 to 40 hex digits, quoted "
     "(e.g. \"82b92a86\"), got '8'"),
    ("    compare_model: {git: a.git, ignore_failing_tests_for: master}\n", "E0701",
     "'ignore_failing_tests_for' is a commit of the compare repository: 4 to 40 hex digits, quoted "
     "(e.g. \"82b92a86\"), got 'master'"),
])
def test_bad_settings_are_reported_where_they_are(tmp_path: Path, diags: Diags, test: str, code: str,
                                                  message: str) -> None:
    assert program(tmp_path, test, diags) is None
    d = diags.take_error(code)
    assert d.message == message
    assert d.span.line >= 12  # inside the test section


def test_a_waiver_is_lower_case_and_zero_tolerances_are_exact(tmp_path: Path, diags: Diags) -> None:
    p = program(tmp_path, "    tolerances: {mass: 0, distance: 0}\n    compare_model: "
                "{git: a.git, ignore_failing_tests_for: '82B92A86'}\n    tests: []\n", diags)
    assert p.test.compare.ignore_failing_tests_for == "82b92a86"
    assert (p.test.tolerances.mass, p.test.tolerances.distance) == (0.0, 0.0)


def test_physical_validity_settings_survive_the_ir_text(tmp_path: Path, diags: Diags) -> None:
    p = program(tmp_path, "    tests:\n      - physical_validity: {severity: error, density: [50, 3e4], "
                "inertia_factor: 4}\n", diags)
    assert p is not None and p.test is not None
    [validity] = p.test.tests
    assert (validity.as_error, validity.density, validity.inertia_factor) == (True, (50.0, 30000.0), 4.0)
    back = parse(dump(p), "arm.ir", diags)
    assert back is not None and back.test == p.test
