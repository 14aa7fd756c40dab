"""Plugging a stage in: what its job carries, skipping after a failed compile, caching, and
`--verify` over stages that skip by their own choice. The stage here stands in for the
model tests (registered the way `mpc.checks` will be) and records what it was given."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest

from mpc.core.diagnostics import Sink
from mpc.pipeline.plan import load_plan
from mpc.pipeline.progress import Quiet
from mpc.pipeline.runner import Runner, RunOptions
from mpc.pipeline.stages import STAGES, Stage, StageJob, StageOutcome
from mpc.pipeline.status import RunStatus

BASE = "package://example-robot-data/robots/double_pendulum_description/urdf/double_pendulum_simple.urdf"


def recording_stage(job: StageJob) -> StageOutcome:
    """Writes what it got into its workdir; skips (not applicable) for the model `na`."""
    assert job.program is not None and job.built is not None
    seen = {"model": job.model, "program": job.program.modelname, "built": str(job.built),
            "out": str(job.out),
            "files": sorted(str(p.relative_to(job.built)) for p in job.built.rglob("*.urdf")),
            "compile": "cached" if job.results["compile"].cached else job.results["compile"].state,
            "compile_summary": job.results["compile"].summary,
            "mr_mention": job.pipeline.get("mr_mention"), "root": str(job.root)}
    (job.workdir / "seen.json").write_text(json.dumps(seen))
    if job.model == "na":
        return StageOutcome("skipped", "nothing to test")
    return StageOutcome("ok", "2 tests passed", details={"passed": 2})


def _model(name: str, remove_beyond: str = "") -> str:
    cut = f", remove_beyond: {remove_beyond}" if remove_beyond else ""
    return textwrap.dedent(f"""\
        model:
          robotname: {name}
          modelname: {name}
          input_models: {{base: {{basefile: "{BASE}"}}}}
          assemble: {{model: base{cut}}}
        """)


@pytest.fixture
def pipeline(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setitem(STAGES, "test", Stage("test", recording_stage, needs=("compile",)))
    (tmp_path / "good.yml").write_text(_model("good"))
    (tmp_path / "bad.yml").write_text(_model("bad", "nowhere"))
    (tmp_path / "na.yml").write_text(_model("na"))
    path = tmp_path / "pipeline.yml"
    path.write_text("pipeline:\n  root: .\n  model_definitions: [good.yml, bad.yml, na.yml]\n")
    return path


def _run(path: Path, **options: object) -> RunStatus:
    sink = Sink()
    plan = load_plan(path, sink)
    assert plan is not None, sink.diagnostics
    return Runner(plan, RunOptions(stages=("compile", "test"), jobs=2, **options), Quiet()).run()  # type: ignore[arg-type]


def _seen(path: Path, model: str) -> dict[str, object]:
    return json.loads((path.parent / "build/.mpc/work" / model / "seen.json").read_text())


def test_a_stage_gets_the_program_and_files_and_is_skipped_after_a_failed_compile(pipeline: Path) -> None:
    status = _run(pipeline)
    good, bad = status.models["good"].stages, status.models["bad"].stages
    assert (good["compile"].state, good["test"].state, good["test"].summary) == ("ok", "ok", "2 tests passed")
    assert good["test"].details == {"passed": 2}
    assert (bad["compile"].state, bad["test"].state, bad["test"].summary, bad["test"].blocked) == (
        "failed", "skipped", "compile did not succeed", True)
    seen = _seen(pipeline, "good")
    build = pipeline.parent / "build"
    assert seen == {"model": "good", "program": "good", "built": str(build / ".mpc/staging/good/out"),
                    "out": str(build / "good"), "files": ["urdf/good.urdf"], "compile": "ok",
                    "compile_summary": "6 files, 0 meshes",
                    "mr_mention": None, "root": str(pipeline.parent)}
    assert status.exit_status() == 1


def test_unchanged_stages_are_cached_and_a_changed_setting_reruns_the_later_stage(pipeline: Path) -> None:
    _run(pipeline)
    again = _run(pipeline)
    states = {s: r.state for s, r in again.models["good"].stages.items()}
    assert states == {"compile": "cached", "test": "cached"}
    pipeline.write_text(pipeline.read_text() + "  mr_mention: '@robots'\n")
    third = _run(pipeline)
    assert {s: r.state for s, r in third.models["good"].stages.items()} == {"compile": "cached", "test": "ok"}
    seen = _seen(pipeline, "good")
    assert (seen["built"], seen["compile"], seen["compile_summary"], seen["mr_mention"]) == (
        str(pipeline.parent / "build/good"), "cached", "6 files, 0 meshes", "@robots")


def test_a_model_added_to_the_pipeline_does_not_rerun_the_others_stages(pipeline: Path) -> None:
    _run(pipeline)
    (pipeline.parent / "new.yml").write_text(_model("new"))
    pipeline.write_text(pipeline.read_text().replace("na.yml]", "na.yml, new.yml]"))
    again = _run(pipeline)
    states = {name: {s: r.state for s, r in m.stages.items()} for name, m in again.models.items()}
    assert states["good"] == {"compile": "cached", "test": "cached"}
    assert states["new"] == {"compile": "ok", "test": "ok"}


def test_verify_counts_a_stage_that_skipped_by_its_own_choice_unless_allowed(pipeline: Path) -> None:
    pipeline.write_text(pipeline.read_text().replace("bad.yml, ", ""))
    status = _run(pipeline)
    assert status.models["na"].stages["test"].state == "skipped"
    assert not status.models["na"].stages["test"].blocked
    assert status.exit_status() == 0
    assert status.exit_status(verify=True) == 1
    assert status.exit_status(verify=True, allow_na=True) == 0
    recorded = json.loads((pipeline.parent / "build/.mpc/status.json").read_text())["exit_status"]
    assert recorded == 0
    _run(pipeline, verify=True)
    recorded = json.loads((pipeline.parent / "build/.mpc/status.json").read_text())["exit_status"]
    assert recorded == 1  # status.json says what `mpc run --verify` returned


def failing_stage(job: StageJob) -> StageOutcome:
    raise RuntimeError("a bug in a stage")


def test_a_stage_that_raises_is_reported_as_a_bug_in_mpc(pipeline: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(STAGES, "test", Stage("test", failing_stage, needs=("compile",)))
    pipeline.write_text(pipeline.read_text().replace("bad.yml, ", ""))
    status = _run(pipeline)
    record = status.models["good"].stages["test"]
    assert record.state == "failed"
    [diag] = record.diagnostics
    assert diag.code == "E0614"
    assert diag.message == ("mpc failed while building model 'good' (a bug in mpc, please report it): "
                            "RuntimeError: a bug in a stage")
    assert "in failing_stage" in diag.notes[0][1]
    assert status.exit_status() == 3
