"""`mpc run` on the twelve-model fleet (examples/fleet): DAG order, parallel workers, a broken
model and its dependant, the cache (no-op, touch, a changed input), `--only`, `--stages`.

The fleet is built once per module (`fleet`); each run the fixture makes is kept, and the
tests read them.
"""

from __future__ import annotations

import json
import os
import pty
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin
import pytest
from lxml import etree

from mpc.pipeline.fingerprint import PACKAGE
from tests.conftest import ERD_PACKAGE
from tests.pipeline.helpers import Run, copy_fleet, mpc, run_json

BUILT = ["arm", "arm_prefixed", "arm_short", "arm_shoulder", "quad", "quad_front", "quad_hind",
         "quad_pair", "pendulum", "finger"]
ARM_CHAIN = ["arm", "arm_prefixed", "arm_short", "arm_shoulder"]


@dataclass
class Fleet:
    pipeline: Path
    build: Path
    cache: Path
    cold: Run
    noop: Run
    touched: Run
    changed: Run
    mtimes_after_cold: dict[str, int]
    mtimes_after_noop: dict[str, int]


def _mtimes(build: Path) -> dict[str, int]:
    return {str(p.relative_to(build)): p.stat().st_mtime_ns for p in build.rglob("*")
            if p.is_file() and ".mpc" not in p.parts}


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Fleet:
    tmp = tmp_path_factory.mktemp("fleet")
    pipeline, cache = copy_fleet(tmp / "fleet"), tmp / "cache"
    build = pipeline.parent / "build"
    cold = run_json(pipeline, "-j", "2", cache=cache)
    after_cold = _mtimes(build)
    noop = run_json(pipeline, "-j", "2", cache=cache)
    after_noop = _mtimes(build)
    os.utime(pipeline.parent / "ur5.urdf")  # newer, same content
    touched = run_json(pipeline, "-j", "2", cache=cache)
    urdf = pipeline.parent / "ur5.urdf"
    urdf.write_text(urdf.read_text().replace('<mass value="3.7"/>', '<mass value="3.9"/>'))
    changed = run_json(pipeline, "-j", "2", cache=cache)
    return Fleet(pipeline, build, cache, cold, noop, touched, changed, after_cold, after_noop)


def test_cold_run_builds_every_model_but_the_broken_one_and_its_dependant(fleet: Fleet) -> None:
    run = fleet.cold
    assert run.returncode == 1
    assert run.states() == {**dict.fromkeys(BUILT, "ok"), "broken": "failed", "broken_child": "skipped"}
    broken = run.status["models"]["broken"]["stages"]["compile"]
    [diag] = broken["diagnostics"]
    assert (diag["code"], diag["span"]["file"], diag["span"]["line"], diag["span"]["col"]) == (
        "E0310", str(fleet.pipeline.parent / "broken.yml"), 6, 46)
    assert diag["message"] == "remove_beyond refers to unknown link 'link9'; did you mean 'link3'?"
    child = run.status["models"]["broken_child"]["stages"]["compile"]
    assert child == {"state": "skipped", "reason": "derived_base 'broken' failed", "seconds": 0.0}
    assert run.status["counts"] == {"ok": 10, "failed": 1, "skipped": 1}
    for name in BUILT:
        assert (fleet.build / name / "urdf").is_dir(), name
    assert not (fleet.build / "broken").exists() and not (fleet.build / "broken_child").exists()
    assert list((fleet.build / ".mpc" / "staging").iterdir()) == []


def test_parents_finish_before_children_start_whatever_the_file_order(fleet: Fleet) -> None:
    """pipeline.yml lists every child before its parents."""
    events = fleet.cold.events
    position = {(e["event"], e["model"]): i for i, e in enumerate(events) if "model" in e}
    parents = {name: m["parents"] for name, m in fleet.cold.status["models"].items()}
    assert parents["quad_pair"] == ["quad_front", "quad_hind"]
    assert parents["arm_shoulder"] == ["arm_short"]
    for name in BUILT:
        for parent in parents[name]:
            assert position[("finish", parent)] < position[("start", name)], (parent, name)


def test_independent_models_build_at_once_up_to_j(fleet: Fleet) -> None:
    running: set[str] = set()
    most = 0
    for e in fleet.cold.events:
        if e["event"] == "start":
            running.add(e["model"])
        elif e["event"] == "finish":
            running.discard(e["model"])
        most = max(most, len(running))
    assert most == 2


def test_derived_models_are_what_their_definitions_say(fleet: Fleet) -> None:
    def links(model: str) -> list[str]:
        [urdf] = (fleet.build / model / "urdf").glob("*.urdf")
        return [e.get("name") for e in etree.parse(str(urdf)).getroot().findall("link")]

    assert links("arm_shoulder") == ["r_world", "r_base_link", "r_base", "r_shoulder_link"]
    assert set(links("quad_pair")) == set(links("quad_front")) | {f"hind_{n}" for n in links("quad_hind")}

    def mass(model: str) -> float:
        [urdf] = (fleet.build / model / "urdf").glob("*.urdf")
        return pin.computeTotalMass(pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer()))

    assert mass("quad_pair") == pytest.approx(mass("quad_front") + mass("quad_hind"), abs=1e-12)
    assert mass("quad_front") < mass("quad")


def test_pipeline_default_export_config_applies_to_models_without_one(fleet: Fleet) -> None:
    pendulum = etree.parse(str(fleet.build / "pendulum/urdf/pendulum.urdf")).getroot()
    assert {m.get("filename") for m in pendulum.iter("mesh")} == {
        "../meshes/stl/base_link.stl", "../meshes/stl/link1.stl", "../meshes/stl/link2.stl"}
    arm = etree.parse(str(fleet.build / "arm/urdf/ur5.urdf")).getroot()  # its own: STL from DAE
    assert all(m.get("filename").endswith(".stl") for m in arm.iter("mesh"))


def test_the_state_lists_the_files_the_build_read(fleet: Fleet) -> None:
    state = json.loads((fleet.build / ".mpc/state/arm.json").read_text())
    files = [d for d in state["deps"] if d[1] != PACKAGE]
    # Files inside the root by their path from it (a clone elsewhere keeps its cache), others absolute.
    assert {"arm.yml", "ur5.urdf"} <= {d[0] for d in files}
    read = {fleet.pipeline.parent / d[0] for d in files}
    meshes = {p.name for p in read if p.suffix in (".dae", ".stl")}
    assert {"base.dae", "shoulder.dae", "wrist3.dae", "base.stl", "wrist3.stl"} <= meshes
    assert all(p.suffix not in (".py", ".pyc", ".so") for p in read)
    assert not any(fleet.cache in p.parents or fleet.build in p.parents for p in read)
    assert all(len(d[3]) == 64 for d in files)
    # ur5.urdf's meshes are package:// paths: where the package was found is a dep too.
    assert [d for d in state["deps"] if d[1] == PACKAGE] == [
        ["package://example-robot-data\0.", PACKAGE, 0, str(ERD_PACKAGE)]]


def test_second_run_rebuilds_nothing(fleet: Fleet) -> None:
    run = fleet.noop
    assert run.started() == []
    assert run.states() == {**dict.fromkeys(BUILT, "cached"), "broken": "failed", "broken_child": "skipped"}
    broken = run.status["models"]["broken"]["stages"]["compile"]
    assert broken["summary"].startswith("unchanged since it failed: E0310 remove_beyond refers to unknown")
    assert broken["details"] == {"cached": True}
    assert broken["diagnostics"][0]["span"]["line"] == 6
    assert fleet.mtimes_after_noop == fleet.mtimes_after_cold
    assert run.returncode == 1


def test_touch_without_a_change_rebuilds_nothing(fleet: Fleet) -> None:
    assert fleet.touched.started() == []
    assert fleet.touched.states()["arm"] == "cached"


def test_a_changed_input_rebuilds_exactly_its_model_and_dependants(fleet: Fleet) -> None:
    run = fleet.changed
    assert sorted(run.started()) == sorted(ARM_CHAIN)
    assert {m for m, s in run.states().items() if s == "ok"} == set(ARM_CHAIN)
    assert {m for m, s in run.states().items() if s == "cached"} == set(BUILT) - set(ARM_CHAIN)
    urdf = etree.parse(str(fleet.build / "arm_short/urdf/ur5_short.urdf"))
    masses = [e.get("value") for e in urdf.iter("mass")]
    assert "3.9" in masses and "3.7" not in masses


def test_status_table_on_stdout(fleet: Fleet) -> None:
    done = mpc("run", fleet.pipeline, cache=fleet.cache)
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert lines[0].split() == ["model", "compile", "time", "note"]
    assert lines[1].split() == ["arm", "cached"]
    assert lines[5].split()[:3] == ["broken", "failed", "unchanged"]
    assert lines[6].split() == ["broken_child", "skipped", "derived_base", "'broken'", "failed"]
    assert lines[-2] == "12 models: 10 cached, 1 failed, 1 skipped in " + lines[-2].split(" in ")[1]
    assert lines[-1] == f"status: {fleet.build / '.mpc/status.json'}"
    assert "broken.yml:6:46: error[E0310]: remove_beyond refers to unknown link 'link9'" in done.stderr


def test_only_builds_the_named_models_and_keeps_the_others(fleet: Fleet) -> None:
    before = _mtimes(fleet.build)
    run = run_json(fleet.pipeline, "--only", "pendulum", "quad_hind.yml", "--force", cache=fleet.cache)
    assert sorted(run.started()) == ["pendulum", "quad_hind"]
    assert set(run.status["models"]) == {"pendulum", "quad_hind"}
    assert run.returncode == 0
    after = _mtimes(fleet.build)
    assert set(after) == set(before)
    changed = {f for f in after if after[f] != before[f]}
    assert changed <= {f for f in after if f.startswith(("pendulum/", "quad_hind/"))}
    assert after["arm/urdf/ur5.urdf"] == before["arm/urdf/ur5.urdf"]
    state = json.loads((fleet.build / ".mpc/state/quad_pair.json").read_text())
    assert state["stages"]["compile"]["fingerprint"] == state["fingerprint"]


def test_only_an_unknown_model_is_a_usage_error(fleet: Fleet) -> None:
    done = mpc("run", fleet.pipeline, "--only", "quad_pairs", cache=fleet.cache)
    assert done.returncode == 2
    assert done.stderr == (f"mpc run: error: --only: no model 'quad_pairs' in '{fleet.pipeline}'; "
                           "did you mean 'quad_pair'?\n")


@pytest.mark.parametrize(("stages", "message"), [
    ("compiel", "unknown stage 'compiel'; did you mean 'compile'? (stages: compile, test, deploy)"),
])
def test_an_unknown_stage_is_a_clean_usage_error(fleet: Fleet, stages: str, message: str) -> None:
    done = mpc("run", fleet.pipeline, "--stages", stages, cache=fleet.cache)
    assert (done.returncode, done.stdout, done.stderr) == (2, "", f"mpc run: error: {message}\n")


def test_verify_fails_when_a_model_failed_and_passes_on_a_clean_selection(fleet: Fleet) -> None:
    assert mpc("run", fleet.pipeline, "--verify", cache=fleet.cache).returncode == 1
    clean = mpc("run", fleet.pipeline, "--verify", "--only", "quad_pair", "finger", cache=fleet.cache)
    assert clean.returncode == 0, clean.stderr


def test_on_a_terminal_a_live_display_then_the_table(fleet: Fleet) -> None:
    """stdout and stderr on a pseudo-terminal: rich's progress display (finished models
    printed above it), then the coloured table."""
    main, side = pty.openpty()
    argv = [sys.executable, "-m", "mpc.cli.main", "run", str(fleet.pipeline), "--only", "pendulum",
            "finger", "--force", "-j", "2"]
    proc = subprocess.Popen(argv, stdin=side, stdout=side, stderr=side, close_fds=True,
                            env={**os.environ, "MPC_CACHE_DIR": str(fleet.cache), "COLUMNS": "100"})
    os.close(side)
    chunks = []
    while True:
        try:
            data = os.read(main, 65536)
        except OSError:  # the terminal closed: the run ended
            break
        if not data:
            break
        chunks.append(data)
    os.close(main)
    assert proc.wait(timeout=120) == 0
    text = b"".join(chunks).decode("utf-8", "replace")
    plain = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text)
    assert plain != text  # a live, coloured display
    assert "2 models" in plain  # the progress bar's label
    assert re.search(r"✓ pendulum ok \d+ files, 3 meshes", plain)
    assert "2 models: 2 ok in" in plain


def test_the_longest_remaining_path_starts_first(fleet: Fleet) -> None:
    """No model was built before, so each counts alike: the arm chain (4 models deep) starts
    first, then the quad diamond (3 deep), though pipeline.yml lists them last."""
    assert fleet.cold.started()[:2] == ["arm", "quad"]


def test_status_json_records_when_each_built_model_started_and_its_wall_time(fleet: Fleet) -> None:
    status = fleet.cold.status
    started = [*BUILT, "broken"]
    assert sorted(started, key=lambda m: status["models"][m]["started"]) == fleet.cold.started()
    for name in started:
        model = status["models"][name]
        compile_ = model["stages"]["compile"]["seconds"]
        assert 0 < compile_ <= model["seconds"], name
        assert 0 <= model["started"] <= model["started"] + model["seconds"] <= status["seconds"], name
    assert "started" not in status["models"]["broken_child"]  # skipped: no worker
    assert all("started" not in m and "seconds" not in m for m in fleet.noop.status["models"].values())
