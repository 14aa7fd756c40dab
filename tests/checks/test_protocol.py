"""The protocol (Markdown, JSON, JUnit XML) and the runner's promises: repeated names, waivers,
skipped is not passed, a raising test does not end the others, PyBullet's console is kept."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from mpc.checks import Protocol, run_model_tests
from mpc.checks.protocol import Result, Tolerance, failed, passed, skipped
from mpc.checks.registry import TESTS
from mpc.core.diagnostics import Sink
from tests.checks.helpers import compile_ok, definition, result, run, statuses, write
from tests.conftest import ERD

SOLO = ERD / "solo_description/robots/solo12.urdf"


def sample() -> Protocol:
    p = Protocol(model="arm-model", compare="`ref` at commit `0123abcd`")
    within = (Tolerance("distance", 0.003, "m"),)
    p.add(passed("compare_com", "COM within", figure=0.001, unit="m", tolerances=within))
    p.add(failed("compare_com", "COM 4.5 mm off", figure=0.0045, unit="m", tolerances=within,
                 details=("base_link: Δ = +0.0045 m",)))
    p.add(skipped("total_mass", "no expected mass"))
    p.add(Result(name="load_in_pybullet", status="passed", reason="loaded", log="b3Printf: <robot> & co"))
    return p


def test_repeated_names_get_numbers_and_a_failure_fails_the_protocol() -> None:
    p = sample()
    assert [r.name for r in p.results] == ["compare_com", "compare_com 2", "total_mass", "load_in_pybullet"]
    assert p.failed
    assert p.counts() == {"passed": 2, "failed": 1, "waived": 0, "skipped": 1}


def test_a_waiver_turns_failures_into_waived_and_only_failures() -> None:
    p = Protocol(model="m", waiver="the compare model is at commit 82b92a86")
    p.add(failed("compare_masses", "total mass differs"))
    p.add(skipped("total_mass", "no expected mass"))
    p.add(passed("compare_com", "fine"))
    assert statuses(p) == {"compare_masses": "waived", "total_mass": "skipped", "compare_com": "passed"}
    assert p.results[0].reason == "total mass differs (waived: the compare model is at commit 82b92a86)"
    assert not p.failed


def test_markdown_has_a_row_per_test_with_figure_and_tolerance() -> None:
    text = sample().markdown()
    assert text.startswith("## Model tests of `arm-model`: **failed** (2 passed, 1 failed, 1 skipped)\n")
    assert ("| `compare_com 2` | ❌ failed | 0.0045 m | `distance` ≤ 0.003 m (absolute) | COM 4.5 mm off |"
            in text)
    assert "| `total_mass` | ⏭️ skipped |  |  | no expected mass |" in text
    assert "--- output ---\nb3Printf: <robot> & co" in text


def test_junit_is_xml_that_ci_reads() -> None:
    root = ET.fromstring(sample().junit())
    suite = root.find("testsuite")
    assert suite is not None
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("4", "1", "1")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert cases["compare_com 2"].find("failure").get("message") == "COM 4.5 mm off"
    assert "base_link: Δ = +0.0045 m" in cases["compare_com 2"].find("failure").text
    assert cases["total_mass"].find("skipped").get("message") == "skipped: no expected mass"
    assert cases["load_in_pybullet"].find("system-out").text == "b3Printf: <robot> & co"
    assert len(cases["compare_com"]) == 0


def test_write_puts_three_files(tmp_path: Path) -> None:
    sample().write(tmp_path)
    data = json.loads((tmp_path / "test_protocol.json").read_text())
    assert data["failed"] is True
    assert data["tests"][1] == {
        "name": "compare_com 2", "status": "failed", "reason": "COM 4.5 mm off", "figure": 0.0045,
        "unit": "m",
        "tolerances": [{"name": "distance", "value": 0.003, "unit": "m", "kind": "absolute"}],
        "details": ["base_link: Δ = +0.0045 m"], "log": ""}
    assert (tmp_path / "test_protocol.md").read_text() == sample().markdown()
    ET.parse(tmp_path / "test_protocol.junit.xml")


def test_a_test_that_raises_does_not_end_the_others(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(ctx, test):
        return 1 / 0

    monkeypatch.setitem(TESTS, "compare_amount_joints", broken)
    tests = "      - compare_amount_joints\n      - load_in_pybullet\n"
    write(tmp_path / "m.yml", definition(SOLO, "solo", tests))
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")
    crashed = result(protocol, "compare_amount_joints")
    assert crashed.status == "failed"
    assert crashed.reason.startswith("the test itself failed (a bug in mpc, please report it: "
                                     "ZeroDivisionError: division by zero at test_protocol.py:")
    assert [r.name for r in protocol.results] == ["compare_amount_joints", "load_in_pybullet",
                                                  "topological_self_consistency", "file_consistency",
                                                  "physical_validity"]
    assert statuses(protocol)["load_in_pybullet"] == "passed"


def test_a_loader_that_raises_fails_the_tests_with_the_reason(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """Even a bug in reading a model (here: the compare model's reader raises) leaves a
    protocol whose compare tests fail with the exception, and the others pass."""
    from mpc.checks import models

    original = models.read_model

    def broken_for_the_compare_model(path, sink):
        if path.is_relative_to(tmp_path / "ref"):
            raise RuntimeError("reader broke")
        return original(path, sink)

    write(tmp_path / "ref.yml", definition(SOLO, "solo", "      - compare_amount_joints\n"))
    compile_ok(tmp_path / "ref.yml", tmp_path / "ref")
    tests = "      - compare_amount_joints\n      - load_in_pybullet\n"
    write(tmp_path / "m.yml", definition(SOLO, "solo", tests, compare="      path: ref\n"))
    result_ = compile_ok(tmp_path / "m.yml", tmp_path / "out")
    monkeypatch.setattr(models, "read_model", broken_for_the_compare_model)
    sink = Sink()
    protocol = run_model_tests(result_.program, tmp_path / "out", sink, workdir=tmp_path / "work",
                               robot=result_.robot)
    s = statuses(protocol)
    assert (s["compare_amount_joints"], s["load_in_pybullet"]) == ("failed", "passed")
    assert result(protocol, "compare_amount_joints").reason.startswith(
        "the compare model cannot be loaded: a bug in mpc, please report it: RuntimeError: reader broke at ")
    assert [d.code for d in sink.diagnostics] == ["E0704"]


def test_pybullet_failure_keeps_its_console_and_a_missing_mesh_fails_the_double_check(tmp_path: Path) -> None:
    tests = "      - process_double_check\n      - load_in_pybullet\n"
    write(tmp_path / "m.yml", definition(SOLO, "solo", tests))
    built = compile_ok(tmp_path / "m.yml", tmp_path / "out")
    lost = sorted((tmp_path / "out" / "meshes").rglob("*.stl"))[0]
    lost.unlink()
    protocol = run_model_tests(built.program, tmp_path / "out", Sink(), workdir=tmp_path / "work",
                               robot=built.robot)
    bullet = result(protocol, "load_in_pybullet")
    assert bullet.status == "failed"
    assert bullet.reason.startswith("PyBullet cannot load 'solo.urdf': Cannot load URDF file.")
    assert lost.name in bullet.log  # b3Warning: cannot find '…' in any directory in urdf path
    double = result(protocol, "process_double_check")
    assert double.status == "failed" and lost.name in double.reason


def test_an_output_that_was_not_compiled_fails_every_test(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", "      - load_in_pybullet\n"))
    built = compile_ok(tmp_path / "m.yml", tmp_path / "out")
    sink = Sink()
    (tmp_path / "empty").mkdir()
    protocol = run_model_tests(built.program, tmp_path / "empty", sink, workdir=tmp_path / "work")
    assert set(statuses(protocol).values()) == {"failed"}
    assert [d.code for d in sink.diagnostics] == ["E0705"]
    assert sink.diagnostics[0].message == \
        f"cannot test 'solo-model': '{tmp_path / 'empty/urdf/solo.urdf'}' does not exist: " \
        "compile the model first"


def test_junit_drops_characters_xml_cannot_hold_and_lxml_reads_it(tmp_path: Path) -> None:
    """A console may print escape sequences or NUL; XML 1.0 cannot hold them even escaped."""
    from lxml import etree

    p = Protocol(model="m\x01")
    p.add(failed("compare_com", "off by \x1b[31m5 mm\x1b[0m", details=("a\x00b",)))
    p.add(Result(name="load_in_pybullet", status="passed", reason="loaded", log="warn\x07ing\n"))
    p.add(skipped("total_mass", "no \x0bexpected mass"))
    p.write(tmp_path)
    suite = etree.parse(str(tmp_path / "test_protocol.junit.xml")).getroot().find("testsuite")
    assert suite.get("name") == "m"
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert cases["compare_com"].find("failure").get("message") == "off by [31m5 mm[0m"
    assert cases["compare_com"].find("failure").text == "ab"
    assert cases["load_in_pybullet"].find("system-out").text == "warning\n"
    assert cases["total_mass"].find("skipped").get("message") == "skipped: no expected mass"


def test_importing_the_checks_loads_no_heavy_library() -> None:
    """Pinocchio, PyBullet, trimesh and GitPython load only when a test uses them."""
    import subprocess
    import sys

    code = ("import sys, mpc.checks, mpc.checks.runner; "
            "print(sorted(m for m in ('pinocchio', 'pybullet', 'trimesh', 'git') if m in sys.modules))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout == "[]\n"
