"""The stages a pipeline runs for each model (compile, test, deploy) → a registry of functions.

A stage is a function `(job: StageJob) -> StageOutcome`, registered under its name with
the stages of the same model it needs. The runner calls the selected stages in the
order of `KNOWN` inside one worker process per model; status, skipping and caching are
the runner's, the same for every stage. `test` and `deploy` are adapters that import their
packages (checks/, deploy/) when they run, so `mpc check` never does.

`deploy` needs only `compile`: a model whose tests failed is deployed too, to the failure
branch, with the protocol in its merge request (kept in the test stage's details, so it
is there also when the test stage is cached).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.record import record

if TYPE_CHECKING:
    from mpc.compiler.driver import Options
    from mpc.compiler.schema.definition import PipelineSection
    from mpc.ir.program import Program
    from mpc.ir.robot import Robot

KNOWN = ("compile", "test", "deploy")  # every stage name, in the order they run


@record(frozen=False)
class StageOutcome:
    """What a stage did for one model.

    state: ok, failed, or skipped (the stage had nothing to do, e.g. `do_not_deploy`; it is
        never cached, and `--verify` counts it as not done unless `--allow-na`).
    summary: one line for the status table. diagnostics: what it reported (besides `job.sink`).
    details: JSON data for status.json (figures, a protocol, a pushed commit); kept in the
        model's state when the stage succeeded, so later stages see it also in a run where
        this stage is cached.
    data: any value for the later stages of the same model in this run; stays in the
        worker, not recorded.
    cached: set by the runner on the outcome of a stage that did not run because its
        result from an earlier run still holds (then state "ok", summary, details; no data).
    """

    state: Literal["ok", "failed", "skipped"]
    summary: str = ""
    diagnostics: list[Diagnostic] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)
    data: Any = None
    cached: bool = False


@record(frozen=False)
class StageJob:
    """Everything a stage gets for one model (one job per model, shared by its stages).

    model: the modelname. definition: the definition file.
    out: the model's output folder (`<build>/<modelname>`); until the run ends it holds the
        previous output (what tests compare against).
    built: the folder with this run's model files: a staging folder when compile ran in
        this run (moved to `out` by the runner once the worker succeeded), `out` when
        compile was cached. None until compile succeeded or was found cached.
    staging: where compile writes. workdir: a scratch folder of this model (kept until the
        next run of the model, e.g. for logs and clones).
    pipeline: the `pipeline` mapping of pipeline.yml as written (validated); root: its
        workspace root, resolved; pipeline_file: that file; pipeline_section: the mapping
        validated.
    options: compile options (packages, the pipeline's defaults hook).
    sink: where the running stage reports (a fresh one per stage).
    program, robot: set by compile (or, when compile is cached, program by `ensure_program`).
    results: outcomes of the earlier stages, by name (cached ones with `cached` set).
    """

    model: str
    definition: Path
    out: Path
    staging: Path
    workdir: Path
    pipeline: dict[str, Any]
    root: Path
    options: Options
    pipeline_file: Path | None = None
    pipeline_section: PipelineSection | None = None
    sink: Sink = field(default_factory=Sink)
    built: Path | None = None
    program: Program | None = None
    robot: Robot | None = None
    results: dict[str, StageOutcome] = field(default_factory=dict)


@record
class Stage:
    """A registered stage: its name, its function, and the stages it needs to have
    succeeded (or been cached) for the same model; otherwise it is skipped."""

    name: str
    run: Callable[[StageJob], StageOutcome]
    needs: tuple[str, ...] = ()


STAGES: dict[str, Stage] = {}


def register(stage: Stage) -> None:
    if stage.name not in KNOWN:
        raise ValueError(f"unknown stage name '{stage.name}'; known: {', '.join(KNOWN)}")
    STAGES[stage.name] = stage


def stages_with_needs(selected: tuple[str, ...]) -> tuple[str, ...]:
    """The selected stages and every stage they need, in the order stages run."""
    wanted = set(selected)
    todo = list(selected)
    while todo:
        for need in STAGES[todo.pop()].needs:
            if need not in wanted:
                wanted.add(need)
                todo.append(need)
    return tuple(s for s in KNOWN if s in wanted)


def ensure_program(job: StageJob) -> bool:
    """Give a job whose compile was cached its program (the front end only); False on errors."""
    if job.program is not None:
        return True
    from mpc.compiler.front_end import load_program

    job.program = load_program(job.definition, job.sink, job.options)
    job.built = job.out if job.program is not None else None
    return job.program is not None


def first_error(diagnostics: list[Diagnostic]) -> str:
    error = next((d for d in diagnostics if d.severity is Severity.ERROR), None)
    return f"{error.code} {error.message}" if error else ""


def compile_stage(job: StageJob) -> StageOutcome:
    """Compile the model into `job.staging` (compiler/driver.py)."""
    from mpc.compiler.driver import compile_model

    result = compile_model(job.definition, job.sink, replace(job.options, out=job.staging, target=job.out))
    job.program, job.robot = result.program, result.robot
    if result.out is None:
        return StageOutcome("failed", first_error(job.sink.diagnostics))
    job.built = result.out
    files = [p for p in result.out.rglob("*") if p.is_file()]
    meshes = sum("meshes" in p.relative_to(result.out).parts for p in files)
    n = len(files) - meshes
    return StageOutcome("ok", f"{n} file{'s' * (n != 1)}, {meshes} mesh{'es' * (meshes != 1)}",
                        details={"files": len(files), "meshes": meshes})


register(Stage("compile", compile_stage))


def test_stage(job: StageJob) -> StageOutcome:
    """Run the model tests (checks/) on this run's build; the protocol goes to the workdir."""
    from mpc.checks import run_model_tests

    if not ensure_program(job):
        return StageOutcome("failed", first_error(job.sink.diagnostics))
    assert job.program is not None and job.built is not None
    protocol = run_model_tests(job.program, job.built, job.sink, workdir=job.workdir, robot=job.robot)
    protocol.write(job.workdir)
    return StageOutcome("failed" if protocol.failed else "ok", protocol.summary(),
                        details={"protocol": str(job.workdir / "test_protocol.md"),
                                 "markdown": protocol.markdown(), "failed": protocol.failed},
                        data=protocol)


def deploy_stage(job: StageJob) -> StageOutcome:
    """Deploy this run's build (deploy/) with the pipeline's settings and the test protocol."""
    from mpc.deploy import DeploySettings, deploy_model

    if not ensure_program(job) or job.pipeline_file is None or job.pipeline_section is None:
        return StageOutcome("failed", first_error(job.sink.diagnostics))
    assert job.program is not None and job.built is not None
    settings = DeploySettings.from_pipeline(job.pipeline_section, job.pipeline_file.resolve().parent,
                                            job.sink)
    tested = job.results.get("test")
    tests = tested.details if tested is not None else {}
    from mpc.checks.diff_review import review_of

    result = deploy_model(job.program, job.built, settings, job.sink,
                          protocol_markdown=tests.get("markdown"), tests_failed=bool(tests.get("failed")),
                          pictures=job.workdir / "test_pictures" if tested is not None else None,
                          review=review_of(job.program, job.built.resolve()))
    if not result.ok:
        return StageOutcome("failed", first_error(job.sink.diagnostics))
    if result.skipped:
        return StageOutcome("skipped", "do_not_deploy")
    summary = (f"pushed {result.commit[:10]} to {result.branch}" if result.pushed and result.commit
               else "nothing changed")
    return StageOutcome("ok", summary, details={"remote": result.remote, "branch": result.branch,
                                                "commit": result.commit, "pushed": result.pushed})


register(Stage("test", test_stage, needs=("compile",)))
register(Stage("deploy", deploy_stage, needs=("compile",)))
