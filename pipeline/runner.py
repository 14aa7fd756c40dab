"""A plan and run options → every selected model built (or found cached), in DAG order, in
parallel worker processes; the run's status.

A model starts when its parents in the selection have finished. A model whose parent
failed (or was skipped) is skipped with that reason; the others go on. Before starting a
model the runner compares its fingerprint with the state of its last build and skips the
stages that are unchanged. A worker builds into a staging folder; the runner moves the
result into place only after the worker succeeded, so a failed, killed or interrupted
build leaves the previous output as it was.
"""

from __future__ import annotations

import contextlib
import gc
import os
import shutil
import signal
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from mpc.core.cores import usable_cores
from mpc.core.diagnostics import Diagnostic, Severity
from mpc.core.files import describe
from mpc.core.record import record
from mpc.core.span import Span
from mpc.core.version import source_version
from mpc.pipeline import schedule
from mpc.pipeline.fingerprint import with_deps
from mpc.pipeline.freshness import Freshness
from mpc.pipeline.plan import Plan, PlannedModel
from mpc.pipeline.stages import StageJob, StageOutcome, first_error
from mpc.pipeline.status import (
    ModelRecord,
    RunStatus,
    StageRecord,
    diagnostics_from_json,
    diagnostics_json,
    past,
)
from mpc.pipeline.store import Store

if TYPE_CHECKING:
    from multiprocessing.connection import Connection
    from multiprocessing.process import BaseProcess

    from mpc.compiler.driver import Options


@record(frozen=False)
class RunOptions:
    """What to run: the stages (each with the stages it needs), the models (`only`; empty:
    all), how many workers, whether to ignore the cache, the build folder (None:
    `<root>/build`), package folders, whether warnings fail a stage, and how the exit status
    is counted (`--verify`, `--allow-na`; recorded in status.json)."""

    stages: tuple[str, ...] = ("compile",)
    only: tuple[str, ...] = ()
    jobs: int = field(default_factory=usable_cores)
    force: bool = False
    build: Path | None = None
    package_map: dict[str, Path] = field(default_factory=dict)
    werror: bool = False
    verify: bool = False
    allow_na: bool = False
    post_processing: bool = True  # --no-post-processing: False


class Reporter(Protocol):
    """Progress of a run (pipeline/progress.py)."""

    def planned(self, status: RunStatus, models: list[str]) -> None: ...
    def started(self, model: str, pid: int) -> None: ...
    def finished(self, model: str, record: ModelRecord) -> None: ...
    def tick(self) -> None: ...
    def close(self) -> None: ...


@record(frozen=False)
class _Running:
    """A model whose worker runs: its process and the pipe it answers on; `pre`, its
    fingerprint before building (freshness.before_build); the stages it runs and those that
    were cached; when it started; and its message, once received."""

    model: str
    process: BaseProcess
    conn: Connection
    pre: str
    run: list[str]
    cached: list[str]
    started: float
    message: dict[str, Any] | None = None


class Runner:
    """Runs one plan once (see the module docstring)."""

    def __init__(self, plan: Plan, opts: RunOptions, reporter: Reporter) -> None:
        self.plan, self.opts, self.reporter = plan, opts, reporter
        self.store = Store(opts.build or plan.root / "build")
        self.parents = plan.parents()
        self.selected = [n for n in plan.models if not opts.only or n in opts.only]
        self.status = RunStatus(str(plan.file), opts.stages, opts.jobs)
        self.fingerprints: dict[str, str | None] = {}  # compile fingerprints of finished models
        self.done: set[str] = set()
        self.running: dict[str, _Running] = {}
        self.shared: set[str] = set()  # modules finished workers imported (_preload)
        self.status_error: str | None = None  # why status.json could not be written
        self.start = time.perf_counter()  # when the run started
        self.freshness = Freshness(plan, self.store, opts.stages, opts.package_map, opts.werror, opts.force,
                                   opts.post_processing)

    # -- the loop ----------------------------------------------------------------------------

    def run(self) -> RunStatus:
        start = self.start = time.perf_counter()
        self.store.lock()
        try:
            priority = self._priorities()
            waiting = sorted(self.selected, key=lambda n: -priority[n])
            self.reporter.planned(self.status, waiting)
            queue: dict[str, tuple[str, str, list[str]]] = {}  # ready to build, by model
            try:
                while waiting or queue or self.running:
                    progressed = False
                    for name in list(waiting):
                        if self._ready(name):
                            waiting.remove(name)
                            decided = self._decide(name)
                            if decided is not None:
                                queue[name] = decided
                            progressed = True
                    while queue and len(self.running) < max(1, self.opts.jobs):
                        name = schedule.next_model(list(queue), priority,
                                                   (self.sources[r] for r in self.running), self.sources)
                        # the builds that will run side by side (those waiting count: most build)
                        side_by_side = min(max(1, self.opts.jobs),
                                           len(self.running) + len(queue) + len(waiting))
                        with _uninterrupted():  # a started worker is always in self.running
                            self._start(*queue.pop(name), side_by_side)
                        progressed = True
                    if self.running:
                        self._wait()
                    elif not progressed and waiting:  # cannot happen: parents always finish
                        for name in waiting:
                            self._finish_all(name, "skipped", "its parents never finished", blocked=True)
                        waiting.clear()
                    self.reporter.tick()
            except KeyboardInterrupt:
                self._interrupt()
        finally:
            self.status.seconds = time.perf_counter() - start
            try:
                self.store.save_status(self.status.to_json(self.opts.verify, self.opts.allow_na))
            except OSError as e:
                self.status_error = e.strerror or str(e)
            self.store.unlock()
        return self.status

    def _priorities(self) -> dict[str, float]:
        """The longest remaining path from each model, in expected seconds (pipeline/schedule.py)."""
        names = [n for n in self.parents if n in self.selected]
        known = schedule.last_seconds(self.store.last_status(), {n: self.store.state(n) for n in names})
        seconds = schedule.expected_seconds(self.parents, known)
        return schedule.priorities({n: [p for p in self.parents[n] if p in self.selected] for n in names},
                                   seconds)

    @cached_property
    def sources(self) -> dict[str, frozenset[str]]:
        """The basefiles each model reads (two models reading one convert the same meshes)."""
        return {n: schedule.sources(m.definition, m.data) for n, m in self.plan.models.items()}

    def _ready(self, name: str) -> bool:
        model = self.plan.models[name]
        return model.failed or all(p not in self.selected or p in self.done for p in model.parents)

    # -- deciding: fail, skip, cached, or build ---------------------------------------------

    def _decide(self, name: str) -> tuple[str, str, list[str]] | None:
        """Finish the model now (failed in planning, blocked, cached) or return what to build."""
        model = self.plan.models[name]
        record = self._record(model)
        unusable = self.store.unusable_state(name)
        if unusable is not None:  # said at the damaged file, set aside: the build rewrites the state
            aside = self.store.set_aside(name)
            line, col = self.store.unusable_at(name)
            where = Span(str(aside), line, col) if aside else Span.of_file(str(self.store.state_file(name)))
            kept = f"; it is kept as {aside.name}" if aside else ""
            record.warnings.append(Diagnostic(
                Severity.WARNING, "W0640", f"the state of model '{name}' from an earlier run is unusable "
                f"({unusable}); the model is built again{kept}", where))
        if model.failed:
            errors = [d for d in model.diagnostics if d.severity is Severity.ERROR]
            self._finish_all(name, "failed", first_error(errors), diagnostics=errors)
            return None
        for parent in model.parents:
            if parent in self.selected and self.fingerprints.get(parent) is None:
                state = self.status.models[parent].stages[self.opts.stages[0]].state
                self._finish_all(name, "skipped", f"derived_base '{parent}' {past(state)}", blocked=True)
                return None
        pre = self.freshness.before_build(model, self.fingerprints)
        failure = self.freshness.last_failure(name, pre)
        if failure is not None:
            self._finish_all(name, "failed", "unchanged since it failed: " + failure["summary"],
                             diagnostics_from_json(failure["diagnostics"]), details={"cached": True})
            return None
        cached = self.freshness.cached_stages(name, pre)
        if len(cached) == len(self.opts.stages):
            state = self.store.state(name)
            for stage in self.opts.stages:
                record.stages[stage] = StageRecord("cached",
                                                   fingerprint=state["stages"][stage].get("fingerprint"))
            self.fingerprints[name] = state["fingerprint"]
            self._done(name)
            return None
        return name, pre, cached

    # -- workers -----------------------------------------------------------------------------

    @cached_property
    def options(self) -> Options:
        """Compile options of every worker (made when the first one starts: a run where all
        is cached never imports the compiler)."""
        from mpc.compiler.driver import Options
        from mpc.core.files import project_root
        from mpc.core.packages import PackageResolver

        # The pipeline's project (its git work tree, else its folder) is every definition's too.
        return Options(resolver=PackageResolver(package_map=dict(self.opts.package_map),
                                                projects=[project_root(self.plan.file.parent)]),
                       defaults=self.plan.defaults, post_processing=self.opts.post_processing)

    def _start(self, name: str, pre: str, cached: list[str], side_by_side: int) -> None:
        from mpc.core.cache import cache_dir
        from mpc.core.cores import share_cores
        from mpc.pipeline import worker

        _preload(self.shared)
        share_cores(side_by_side)  # the worker forks with its share of the cores for its meshes
        model = self.plan.models[name]
        try:
            shutil.rmtree(self.store.staging(name), ignore_errors=True)
            self.store.staging(name).mkdir(parents=True)
            self.store.workdir(name).mkdir(parents=True, exist_ok=True)
        except OSError as e:
            diag = _unwritable(name, model, e)
            self._finish_all(name, "failed", diag.message, diagnostics=[diag])
            return
        job = StageJob(model=name, definition=model.definition, out=self.store.output(name),
                       staging=self.store.staging(name) / "out", workdir=self.store.workdir(name),
                       pipeline=self.plan.settings, root=self.plan.root, options=self.options,
                       pipeline_file=self.plan.file, pipeline_section=self.plan.section)
        done = self.store.state(name).get("stages", {})
        for stage in cached:
            kept = done.get(stage, {})
            job.results[stage] = StageOutcome("ok", kept.get("summary", ""), details=kept.get("details", {}),
                                              cached=True)
        run = [s for s in self.opts.stages if s not in cached]
        sys.stdout.flush()  # a forked worker must not write out what the runner had buffered
        sys.stderr.flush()
        import multiprocessing  # here: a run where all is cached starts no process

        ctx = multiprocessing.get_context("fork")
        receive, send = ctx.Pipe(duplex=False)
        ignore = [self.store.build.resolve(), cache_dir("x").parent]
        process = ctx.Process(target=worker.main, name=f"mpc {name}",
                              args=(job, run, cached, send, ignore, self.opts.werror))
        # What the runner holds is in the collector's permanent generation as the worker forks: the
        # worker's collections then never walk it, which wrote into each object and so copied each
        # page it shares with the runner (cold 50-model run: -j1 and -j2 7% and 5% faster).
        gc.freeze()
        now = time.perf_counter()  # before the fork: the worker's stages may start before it returns
        try:
            process.start()
        finally:
            gc.unfreeze()  # the runner's own garbage is still collected
        send.close()
        self.running[name] = _Running(name, process, receive, pre, run, cached, now)
        self.status.models[name].started = now - self.start
        self.reporter.started(name, process.pid or 0)

    def _wait(self) -> None:
        from multiprocessing.connection import wait

        handles: dict[Any, _Running] = {}
        for r in self.running.values():
            handles[r.conn] = r
            handles[r.process.sentinel] = r
        for ready in wait(list(handles), timeout=0.1):
            r = handles[ready]
            if r.model not in self.running:
                continue
            if ready is r.conn:
                try:
                    r.message = r.conn.recv()
                except (EOFError, OSError):
                    pass  # the worker died before it could tell; its exit status says how
                else:
                    self.shared.update((r.message or {}).get("imported", ()))
                    continue  # the worker exits right after sending
            r.process.join()
            r.conn.close()
            del self.running[r.model]
            self.status.models[r.model].seconds = time.perf_counter() - r.started
            # Moving the output into place and saving its state happen together or not at
            # all: an interruption waits until both are done.
            with _uninterrupted():
                try:
                    self._collect(r)
                except OSError as e:  # the output or state could not be written: the model failed
                    diag = _unwritable(r.model, self.plan.models[r.model], e)
                    self._finish_all(r.model, "failed", diag.message, [diag])
                    self._discard(r.model)

    def _collect(self, r: _Running) -> None:
        """Record what a finished worker did; move its output into place when compile succeeded."""
        self._end_group(r.process.pid)
        name, model = r.model, self.plan.models[r.model]
        record = self.status.models[name]
        message = r.message
        if message is None or "internal_error" in message:
            if message is None:
                code = r.process.exitcode or 0
                why = (f"was stopped by signal {signal.Signals(-code).name}" if code < 0
                       else f"ended with exit status {code} without a result")
                diag = Diagnostic(Severity.ERROR, "E0613", f"the build of model '{name}' {why}; "
                                  "its previous output is unchanged", Span.of_file(str(model.definition)))
            else:
                self.status.internal_error = True
                diag = message["internal_error"]  # worker.bug
            for stage in r.cached:
                record.stages[stage] = StageRecord("cached")
            record.stages[r.run[0]] = StageRecord("failed", diag.message, [diag],
                                                  seconds=time.perf_counter() - r.started)
            for stage in r.run[1:]:
                record.stages[stage] = StageRecord("skipped", f"{r.run[0]} did not finish", blocked=True)
            cached_fp = self.store.state(name).get("fingerprint")
            self.fingerprints[name] = cached_fp if "compile" in r.cached else None
            self._discard(name)
            self._done(name)
            return
        self._record_outcomes(r, message)
        self._discard(name)
        self._done(name)

    def _record_outcomes(self, r: _Running, message: dict[str, Any]) -> None:
        from mpc.compiler.driver import replace_folder  # the same swap `mpc compile` does

        name = r.model
        record = self.status.models[name]
        outcomes: dict[str, dict[str, Any]] = message["outcomes"]
        state = self.store.state(name) if "compile" in r.cached else {}
        compiled = outcomes.get("compile", {}).get("state") == "ok"
        if compiled:
            # Without its state, a model is built again: so a state that could not be saved
            # never describes an output it did not make.
            self.store.forget_state(name)
            left = replace_folder(self.store.staging(name) / "out", self.store.output(name))
            if left is not None:
                record.warnings.append(Diagnostic(Severity.WARNING, "W0625", left,
                                                  Span.of_file(str(self.plan.models[name].definition))))
            state = {"model": name, "definition": str(self.plan.models[name].definition), "pre": r.pre,
                     "fingerprint": with_deps(r.pre, message["deps"] or []), "deps": message["deps"] or [],
                     "mpc": source_version(), "stages": {}}
        fp = state.get("fingerprint") if (compiled or "compile" in r.cached) else None
        self.fingerprints[name] = fp
        stages = dict(state.get("stages", {}))
        for stage in self.opts.stages:
            if stage in r.cached:
                record.stages[stage] = StageRecord("cached",
                                                   fingerprint=stages.get(stage, {}).get("fingerprint"))
                continue
            o = outcomes[stage]
            if o["details"].get("internal_error"):
                self.status.internal_error = True
            sfp = self.freshness.stage_fingerprint(fp, stage) if fp else None
            record.stages[stage] = StageRecord(
                o["state"], o["summary"], o["diagnostics"], o["seconds"],
                sfp if o["state"] == "ok" else None, o["details"], o["blocked"])
            if o["state"] == "ok" and sfp:
                stages[stage] = {"fingerprint": sfp, "seconds": round(o["seconds"], 3),
                                 "summary": o["summary"], "details": o["details"]}
            else:
                stages.pop(stage, None)
        if fp is not None:
            self.store.save_state(name, {**state, "stages": stages})
        elif "compile" in outcomes:
            # A failed compile keeps the state of the last success: that output is still there
            # and still matches it, so undoing the change makes the model cached again.
            o = outcomes["compile"]
            self.store.save_state(name, {**self.store.state(name), "failure": {
                "pre": r.pre, "deps": message["deps"] or [], "summary": o["summary"],
                "diagnostics": diagnostics_json(o["diagnostics"])}})

    def _discard(self, name: str) -> None:
        shutil.rmtree(self.store.staging(name), ignore_errors=True)

    def _end_group(self, pid: int | None) -> None:
        """End what the worker's build started and left behind (its process group)."""
        if pid:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)

    def _interrupt(self) -> None:
        """Stop every worker (the run was interrupted); their outputs stay as they were."""
        self.status.interrupted = True
        for r in list(self.running.values()):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(r.process.pid or 0, signal.SIGTERM)
        for r in list(self.running.values()):
            r.process.join(5)
            self._end_group(r.process.pid)
            record = self.status.models[r.model]
            for stage in self.opts.stages:
                record.stages[stage] = StageRecord("cached" if stage in r.cached else "interrupted",
                                                   "the run was interrupted" if stage not in r.cached else "")
            self._discard(r.model)
        self.running.clear()

    # -- records -----------------------------------------------------------------------------

    def _record(self, model: PlannedModel) -> ModelRecord:
        record = ModelRecord(model.name, model.written, model.parents,
                             warnings=[d for d in model.diagnostics if d.severity is not Severity.ERROR])
        self.status.models[model.name] = record
        return record

    def _finish_all(self, name: str, state: str, summary: str, diagnostics: list[Diagnostic] | None = None,
                    blocked: bool = False, details: dict[str, Any] | None = None) -> None:
        """The first stage gets `state`; the later ones are skipped because of it."""
        record = self.status.models.get(name) or self._record(self.plan.models[name])
        first, *rest = self.opts.stages
        record.stages[first] = StageRecord(state, summary, diagnostics or [], blocked=blocked,
                                           details=details or {})
        for stage in rest:
            record.stages[stage] = StageRecord("skipped", summary if state == "skipped" else
                                               f"{first} {past(state)}", blocked=True)
        self.fingerprints[name] = None
        self._done(name)

    def _done(self, name: str) -> None:
        self.done.add(name)
        self.reporter.finished(name, self.status.models[name])


@contextmanager
def _uninterrupted() -> Iterator[None]:
    """Hold SIGINT and SIGTERM until the block is done (they are delivered after it)."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def _unwritable(name: str, model: PlannedModel, error: OSError) -> Diagnostic:
    """E0642: the build folder refused a model's output or state."""
    return Diagnostic(Severity.ERROR, "E0642", f"cannot write the build of model '{name}' "
                      f"({describe(error)}); its previous output is unchanged",
                      model.span)


def _preload(shared: set[str]) -> None:
    """Import what every build uses before forking, so workers share it instead of importing it,
    and what finished workers imported (`worker.shareable`: a pipeline of USD models pays for
    usd-core once, not once per model)."""
    import importlib

    from mpc.backends import urdf  # noqa: F401
    from mpc.compiler import driver, front_end  # noqa: F401
    from mpc.compiler.schema import definition  # noqa: F401  # every node class declared
    from mpc.compiler.schema.base import prepare

    prepare()  # made on first use (schema/base.py): once here, not in every worker
    environment = dict(os.environ)  # what a build is kept by (compiler/build_cache.py): unchanged
    for module in sorted(shared - set(sys.modules)):
        with contextlib.suppress(Exception):  # one that cannot be imported here is imported there
            importlib.import_module(module)
    if dict(os.environ) != environment:
        os.environ.clear()
        os.environ.update(environment)
