"""Bad input to `mpc test` never ends in a traceback or an "internal error": each case gives a
diagnostic or a failed/skipped test with its reason, the other tests still run, and the
protocol is written (its JUnit XML valid, each testcase with the element its status needs)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import git
import pytest
from lxml import etree

from tests.checks.fourbar import FOURBAR_DEFINITION, FOURBAR_URDF
from tests.checks.helpers import EVERY_TEST, definition, edited_urdf, link_el, write
from tests.conftest import ERD
from tests.mpc_command import mpc

SOLO = ERD / "solo_description/robots/solo12.urdf"
EVERY = (EVERY_TEST + "          - move_hyrodyn_model: 0.3\n          - compare_torques\n"
         "          - compare_com\n      - total_mass: 2.5\n      - physical_validity: error\n")
INERTIAL = ('<inertial><origin xyz="0 0 0.1"/><mass value="1"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>')
LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
HINGE = '<axis xyz="1 0 0"/>' + LIMIT


def joint(name: str, kind: str, parent: str, child: str, extra: str = "") -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'{extra}</joint>')


def link(name: str, inertial: str = INERTIAL) -> str:
    return f'<link name="{name}">{inertial}</link>'


# Small models at the edges of what a tree can be.
EDGE_MODELS = {
    "single_link": link("a"),
    "fixed_joints_only": link("a") + joint("j", "fixed", "a", "b") + link("b"),
    "massless_root": link("a", "") + joint("j", "revolute", "a", "b", HINGE) + link("b"),
    "continuous_joint": link("a") + joint("j", "continuous", "a", "b", '<axis xyz="1 0 0"/>') + link("b"),
    "mimic_joint": link("a") + joint("j", "revolute", "a", "b", HINGE) + link("b")
    + joint("k", "revolute", "b", "c", '<origin xyz="0 0 1"/><axis xyz="1 0 0"/>' + LIMIT
            + '<mimic joint="j" multiplier="2" offset="0"/>') + link("c"),
}


def protocol_of(folder: Path, run: subprocess.CompletedProcess[str]) -> dict:
    """The protocol in `folder`, checked: no traceback, no internal error, JUnit XML that lxml
    reads with a <failure> for each failed and a <skipped> for each skipped or waived test."""
    assert run.returncode in (0, 1), run.stderr
    assert "Traceback" not in run.stderr and "internal error" not in run.stderr, run.stderr
    assert "a bug in mpc" not in run.stdout, run.stdout
    data = json.loads((folder / "test_protocol.json").read_text())
    suite = etree.parse(str(folder / "test_protocol.junit.xml")).getroot().find("testsuite")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert list(cases) == [t["name"] for t in data["tests"]]
    wanted = {"passed": [], "failed": ["failure"], "skipped": ["skipped"], "waived": ["skipped"]}
    for t in data["tests"]:
        assert [c.tag for c in cases[t["name"]] if c.tag != "system-out"] == wanted[t["status"]], t
        assert t["status"] == "passed" or t["reason"], t
    assert run.returncode == int(data["failed"])
    return data


def statuses(data: dict) -> dict[str, str]:
    return {t["name"]: t["status"] for t in data["tests"]}


def reasons(data: dict) -> dict[str, str]:
    return {t["name"]: t["reason"] for t in data["tests"]}


@pytest.mark.parametrize("name", sorted(EDGE_MODELS))
def test_edge_models_compared_with_themselves_never_crash(tmp_path: Path, name: str) -> None:
    write(tmp_path / "m.urdf", f'<robot name="r">{EDGE_MODELS[name]}</robot>')
    write(tmp_path / "m.yml", definition(tmp_path / "m.urdf", "r", EVERY, compare="      path: m.urdf\n"))
    data = protocol_of(tmp_path / "out", mpc("test", tmp_path / "m.yml", "-o", tmp_path / "out"))
    s = statuses(data)
    # Everything a model compared with itself can fail: the expected total mass (2.5 kg is
    # only right for the mimic model) and torques of a model with no movable joint (skipped).
    allowed_failures = {"total_mass"}
    assert {n for n, v in s.items() if v == "failed"} <= allowed_failures, data
    if name in ("single_link", "fixed_joints_only"):
        assert s["compare_torques"] == s["compare_torques 2"] == "skipped"
        assert reasons(data)["compare_torques"] == "the compiled model has no actuated joint"


@pytest.mark.parametrize(("compare", "reason"), [
    ("      path: nothing\n", "compare model path 'nothing' does not exist"),  # as the protocol names it
    ("      path: notes.txt\n", "cannot read the compare model 'notes.txt': {tmp}/notes.txt:1:1: "
     "malformed XML in '{tmp}/notes.txt': Start tag expected, '<' not found"),
    ("      path: broken.urdf\n", "cannot read the compare model 'broken.urdf': {tmp}/broken.urdf:1:33: "
     "joint 'j' has no <child link=…>"),
    ("      path: robot.smurf\n", "cannot read the compare model 'robot.smurf': {tmp}/robot.smurf:2:8: "
     "the SMURF lists no URDF or SDF file"),
    ("      git: {tmp}/remote.git\n      branch: nope\n", "cannot get branch 'nope' of compare repository "
     "'{tmp}/remote.git': fatal: Remote branch nope not found in upstream origin"),
    ("      git: {tmp}/remote.git\n      model_in_repo: urdf/other.urdf\n",
     "'urdf/other.urdf' does not exist in the compare model at commit {commit}"),
    ("      git: {tmp}/nothing.git\n", "cannot get the default branch of compare repository "
     "'{tmp}/nothing.git': fatal: repository '{tmp}/nothing.git' does not exist"),
])
def test_a_compare_model_that_cannot_be_loaded_fails_the_compare_tests_only(
        tmp_path: Path, compare: str, reason: str) -> None:
    write(tmp_path / "notes.txt", "not a model\n")
    write(tmp_path / "robot.smurf", "modelname: robot\nfiles: [robot_submechanisms.yml]\n")
    write(tmp_path / "broken.urdf", '<robot name="b"><link name="a"/><joint name="j" type="fixed">'
          '<parent link="a"/></joint></robot>\n')
    bare = tmp_path / "remote.git"
    git.Repo.init(bare, bare=True, initial_branch="master")
    work = git.Repo.clone_from(str(bare), tmp_path / "clone")
    (tmp_path / "clone/urdf").mkdir()
    shutil.copy(SOLO, tmp_path / "clone/urdf/solo.urdf")
    work.index.add(["urdf/solo.urdf"])
    commit = work.index.commit("release").hexsha
    work.remote().push("master")
    write(tmp_path / "m.yml", definition(SOLO, "solo", EVERY, compare=compare.format(tmp=tmp_path)))
    run = mpc("test", tmp_path / "m.yml", "-o", tmp_path / "out")
    data = protocol_of(tmp_path / "out", run)
    why = reason.format(tmp=tmp_path, commit=commit[:12])
    assert f"error[E0704]: {why}\n" in run.stderr
    s = statuses(data)
    compare_tests = {"compare_link_masses", "compare_link_transformations", "compare_amount_joints",
                     "compare_masses", "compare_com", "compare_torques", "compare_link_positions",
                     "compare_torques 2", "compare_com 2", "file_consistency", "topological_self_consistency"}
    assert {n for n, v in s.items() if v == "failed"} == compare_tests
    assert reasons(data)["compare_masses"] == f"the compare model cannot be loaded: {why}"
    shown = Path(compare.split(":", 1)[1].splitlines()[0].strip().format(tmp=tmp_path)).name
    assert f"\n\nCompared with `{shown}`, which could not be loaded.\n" in run.stdout  # no runner's path
    assert s["load_in_pybullet"] == s["total_mass"] == s["move_hyrodyn_model"] == "passed"


def test_built_pointing_at_an_empty_folder_fails_every_test_with_the_reason(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", EVERY))
    (tmp_path / "empty").mkdir()
    run = mpc("test", tmp_path / "m.yml", "--built", tmp_path / "empty")
    data = protocol_of(tmp_path / "empty", run)
    why = f"'{tmp_path}/empty/urdf/solo.urdf' does not exist: compile the model first"
    assert f"error[E0705]: cannot test 'solo-model': {why}" in run.stderr
    assert {t["status"] for t in data["tests"]} == {"failed"}
    assert reasons(data)["load_in_pybullet"] == f"the compiled model cannot be loaded: {why}"


def test_built_with_out_writes_the_protocol_there(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", "      - compare_amount_joints\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "built").returncode == 0
    run = mpc("test", tmp_path / "m.yml", "--built", tmp_path / "built", "-o", tmp_path / "reports")
    data = protocol_of(tmp_path / "reports", run)
    assert statuses(data)["compare_amount_joints"] == "skipped"
    assert not (tmp_path / "built/test_protocol.md").exists()
    assert run.stderr.endswith(f"wrote {tmp_path}/reports/test_protocol.md, test_protocol.json and "
                               "test_protocol.junit.xml\n")


def test_a_protocol_folder_that_is_a_file_is_an_error_not_a_crash(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", "      - compare_amount_joints\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "built").returncode == 0
    write(tmp_path / "reports", "a file\n")
    run = mpc("test", tmp_path / "m.yml", "--built", tmp_path / "built", "-o", tmp_path / "reports")
    assert run.returncode == 1
    assert run.stderr.endswith(f"error: cannot write the test protocol into '{tmp_path}/reports': "
                               "File exists\n")
    assert run.stdout.startswith("## Model tests of `solo-model`: **passed**")  # still printed


def test_built_of_another_model_fails_process_double_check_and_masses_compare(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", EVERY, compare="      path: ref\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "ref").returncode == 0
    other = tmp_path / "other/urdf/solo.urdf"
    other.parent.mkdir(parents=True)
    shutil.copy(ERD / "ur_description/urdf/ur5_robot.urdf", other)
    data = protocol_of(tmp_path / "other", mpc("test", tmp_path / "m.yml", "--built", tmp_path / "other"))
    s = statuses(data)
    assert s["process_double_check"] == s["compare_link_masses"] == "failed"
    assert s["topological_self_consistency"] == "failed"
    assert reasons(data)["process_double_check"].startswith("link 'FL_FOOT' of the definition is missing")


def test_a_link_in_one_model_only_counts_with_its_whole_mass(tmp_path: Path) -> None:
    """The compiled model has a 0.5 kg link the compare model lacks: compare_link_masses
    names it with Δ = +0.5 kg (this raised KeyError before)."""
    def extra(root):
        etree.SubElement(root, "joint", name="extra_joint", type="fixed").extend([
            etree.Element("parent", link="base_link"), etree.Element("child", link="extra")])
        link = etree.SubElement(root, "link", name="extra")
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(inertial, "mass", value="0.5")
        etree.SubElement(inertial, "inertia", ixx="0.01", ixy="0", ixz="0", iyy="0.01", iyz="0", izz="0.01")
        assert link_el(root, "extra") is not None

    model = edited_urdf(SOLO, tmp_path / "in/solo12.urdf", extra)
    write(tmp_path / "ref.yml", definition(SOLO, "solo", "      - compare_amount_joints\n"))
    assert mpc("compile", tmp_path / "ref.yml", "-o", tmp_path / "ref").returncode == 0
    write(tmp_path / "m.yml", definition(model, "solo", "      - compare_link_masses\n",
                                         compare="      path: ref\n"))
    data = protocol_of(tmp_path / "out", mpc("test", tmp_path / "m.yml", "-o", tmp_path / "out"))
    [masses] = [t for t in data["tests"] if t["name"] == "compare_link_masses"]
    assert (masses["status"], masses["figure"]) == ("failed", 0.5)
    assert masses["reason"] == "1 link mass differs by more than 0.01 kg, most 'extra' by +0.5 kg"
    assert statuses(data)["topological_self_consistency"] == "passed"  # an addition is not a break


def test_a_loop_without_motors_fails_the_torque_checks_with_a_hint(tmp_path: Path) -> None:
    """Without `active:` every joint of the four-bar counts as actuated, which over-determines
    the torques: compare_torques fails with that reason (not as a bug in mpc)."""
    write(tmp_path / "fourbar.urdf", FOURBAR_URDF)
    text = FOURBAR_DEFINITION.replace("    crank_joint:\n      active: true\n", "")
    write(tmp_path / "fourbar.yml", text + "  test:\n    compare_model: {path: fourbar.urdf}\n    tests:\n"
          "      - hyrodynChecks:\n          - load_in_hyrodyn\n          - compare_torques\n"
          "          - symmetry_check_torques: [crank, rocker]\n")
    data = protocol_of(tmp_path / "out", mpc("test", tmp_path / "fourbar.yml", "-o", tmp_path / "out"))
    why = ("the actuated joints (crank_joint, coupler_joint, rocker_joint) do not determine their torques "
           "(the mechanism is overactuated: without motors every movable joint counts as actuated; mark "
           "the driven ones `active: true` in `joints`)")
    assert reasons(data)["compare_torques"] == why
    assert reasons(data)["symmetry_check_torques"] == why
    assert statuses(data)["load_in_hyrodyn"] == "passed"


def test_zero_tolerances_are_exact_and_a_model_still_equals_itself(tmp_path: Path) -> None:
    """Tolerances are absolute: at 0 a model compared with its own release passes every test
    (no relative scaling, no noise from reading it twice), and each bound shows as ≤ 0."""
    write(tmp_path / "m.yml", definition(SOLO, "solo", EVERY_TEST + "          - move_hyrodyn_model: 0.3\n"
                                         "          - compare_torques\n", compare="      path: ref\n")
          .replace("  test:\n", "  test:\n    tolerances: {default: 0, mass: 0, rad: 0, distance: 0}\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "ref").returncode == 0
    run = mpc("test", tmp_path / "m.yml", "-o", tmp_path / "out")
    data = protocol_of(tmp_path / "out", run)
    assert set(statuses(data).values()) == {"passed"}, run.stdout
    assert "| `compare_torques 2` | ✅ passed | 0 N·m | `default` ≤ 0 N·m (absolute) |" in run.stdout
    [masses] = [t for t in data["tests"] if t["name"] == "compare_masses"]
    assert masses["tolerances"] == [{"name": "mass", "value": 0.0, "unit": "kg", "kind": "absolute"}]
