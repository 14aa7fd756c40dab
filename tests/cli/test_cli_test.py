"""`mpc test`: compiles (or takes --built), writes the protocol beside the model, prints the
Markdown, and exits 1 only when a test failed and was not waived."""

from __future__ import annotations

import json
from pathlib import Path

from tests.checks.helpers import definition, edited_urdf, link_el, write
from tests.conftest import ERD
from tests.mpc_command import mpc, mpc_process

SOLO = ERD / "solo_description/robots/solo12.urdf"
TESTS = "      - load_in_pybullet\n      - compare_link_masses\n      - hyrodynChecks: [compare_masses]\n"


def test_a_model_against_its_release_passes_and_writes_the_protocol(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", TESTS, compare="      path: ref\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "ref").returncode == 0
    run = mpc_process("test", tmp_path / "m.yml", "-o", tmp_path / "out")
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.startswith("## Model tests of `solo-model`: **passed** (6 passed, 0 failed)\n")
    assert "| `load_in_pybullet` | ✅ passed | 17 links |" in run.stdout
    assert "pybullet build time" not in run.stderr  # PyBullet's console goes into the protocol
    assert "--- output ---\npybullet build time:" in run.stdout
    assert run.stderr.endswith(f"wrote {tmp_path / 'out/test_protocol.md'}, test_protocol.json and "
                               "test_protocol.junit.xml\n")
    data = json.loads((tmp_path / "out/test_protocol.json").read_text())
    assert (data["failed"], data["counts"]["passed"]) == (False, 6)
    assert (tmp_path / "out/urdf/solo.urdf").is_file()
    assert (tmp_path / "out/test_protocol.junit.xml").is_file()


def test_a_failing_test_exits_1_and_built_skips_compiling(tmp_path: Path) -> None:
    write(tmp_path / "ref.yml", definition(SOLO, "solo", TESTS))
    assert mpc("compile", tmp_path / "ref.yml", "-o", tmp_path / "ref").returncode == 0

    def heavier(root):
        mass = link_el(root, "base_link").find("inertial/mass")
        mass.set("value", repr(float(mass.get("value")) + 0.1))

    heavy = edited_urdf(SOLO, tmp_path / "in/solo12.urdf", heavier)
    write(tmp_path / "m.yml", definition(heavy, "solo", TESTS, compare="      path: ref\n"))
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "out").returncode == 0
    (tmp_path / "out/urdf/solo.urdf").touch()
    before = (tmp_path / "out/urdf/solo.urdf").stat().st_mtime_ns
    run = mpc("test", tmp_path / "m.yml", "--built", tmp_path / "out")
    assert run.returncode == 1
    assert "| `compare_masses` | ❌ failed | 0.1 kg | `mass` ≤ 0.01 kg (absolute) |" in run.stdout
    assert (tmp_path / "out/urdf/solo.urdf").stat().st_mtime_ns == before  # not rebuilt
    assert (tmp_path / "out/test_protocol.md").read_text() == run.stdout[:-1]


def test_a_definition_with_errors_is_not_tested(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(SOLO, "solo", "      - total_mass: heavy\n"))
    run = mpc("test", tmp_path / "m.yml", "-o", tmp_path / "out")
    assert run.returncode == 1
    assert "error[E0211]" in run.stderr or "error[E02" in run.stderr
    assert f"error: could not compile '{tmp_path / 'm.yml'}'" in run.stderr
    assert not (tmp_path / "out").exists()
