"""One model's stages, run in a worker process → a message to the runner: each stage's outcome
and the files compile read.

The worker is a forked child in a process group of its own: a SIGTERM to it ends this
build only, and the runner then ends what the build started (mesh workers, commands) and
discards its staging folder. The worker never moves anything into the output folder.
"""

from __future__ import annotations

import os
import signal
import sys
import time
import traceback
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from mpc.core.cache import keep_digests
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.reads import ReadRecorder
from mpc.core.span import Span
from mpc.pipeline.fingerprint import dep_entry, package_entry
from mpc.pipeline.stages import STAGES, StageJob, StageOutcome, ensure_program, first_error


def main(job: StageJob, run: list[str], cached: list[str], conn: Connection, ignore: list[Path],
         werror: bool) -> None:
    """The worker's body: run the stages in `run` (those in `cached` are done already)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the runner stops its workers itself
    # The runner forks with these held (runner._uninterrupted); a worker takes them at once.
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    os.setpgid(0, 0)
    recorder = ReadRecorder(ignore).install()
    before = set(sys.modules)
    try:
        message: dict[str, Any] = run_stages(job, run, cached, recorder, werror)
    except Exception as e:  # a bug in mpc; the runner reports it as one
        message = {"internal_error": bug(job, e)}
    message["imported"] = sorted(m for m in set(sys.modules) - before if shareable(m))
    keep_digests()  # a worker ends without running what is registered to run at exit
    conn.send(message)
    conn.close()


# Libraries (and mpc's own layers) a build imports that the runner may import too, before it
# forks the next worker, so that each worker does not import them again (pxr and numpy are
# 0.2 s of a USD build's start). No module of a command, a test or a stage's tool is here.
SHARED_LAYERS = ("mpc.backends.", "mpc.compiler.", "mpc.core.", "mpc.ir.")
SHARED_LIBRARIES = frozenset({"numpy", "pxr", "lxml", "trimesh", "scipy", "mujoco", "yaml"})


def shareable(module: str) -> bool:
    """Not mujoco.egl: importing it chooses PyOpenGL's platform for the process (its
    environment), which a render sets and unsets itself (backends/scene.py)."""
    if module.startswith("mujoco.egl"):
        return False
    return module.startswith(SHARED_LAYERS) or module.split(".")[0] in SHARED_LIBRARIES


def bug(job: StageJob, error: Exception) -> Diagnostic:
    """E0614 for an exception raised while building `job`'s model, with its traceback."""
    return Diagnostic(Severity.ERROR, "E0614", f"mpc failed while building model '{job.model}' (a bug in "
                      f"mpc, please report it): {type(error).__name__}: {error}",
                      Span.of_file(str(job.definition)), notes=((None, traceback.format_exc()),))


def run_stages(job: StageJob, run: list[str], cached: list[str], recorder: ReadRecorder,
               werror: bool) -> dict[str, Any]:
    """Each stage of `run` in order, skipping one whose needs did not succeed; the message
    for the runner: each stage's outcome, and the files compile read (`deps`, None when
    compile did not run here)."""
    outcomes: dict[str, dict[str, Any]] = {}
    deps = None
    for name in run:
        stage = STAGES[name]
        missing = [n for n in stage.needs if n not in cached and outcomes.get(n, {}).get("state") != "ok"]
        started = time.perf_counter()
        job.sink = Sink(werror=werror)
        if missing:
            outcome = StageOutcome("skipped", f"{missing[0]} did not succeed")
        elif name != "compile" and not ensure_program(job):
            outcome = StageOutcome("failed", first_error(job.sink.diagnostics))
        else:
            try:
                outcome = stage.run(job)
            except Exception as e:  # a bug in mpc (or in a stage): this stage fails, as one
                outcome = StageOutcome("failed", diagnostics=[bug(job, e)], details={"internal_error": True})
        diagnostics = [*job.sink.diagnostics, *outcome.diagnostics]
        if outcome.state == "failed" and not outcome.summary:
            outcome.summary = first_error(diagnostics)
        job.results[name] = outcome
        outcomes[name] = {"state": outcome.state, "summary": outcome.summary, "diagnostics": diagnostics,
                          "details": outcome.details, "seconds": time.perf_counter() - started,
                          "blocked": bool(missing)}
        if name == "compile":
            deps = [e for p in recorder.inputs() if (e := dep_entry(p, job.root)) is not None]
            deps += [package_entry(package, near, found, job.root)
                     for (package, near), found in recorder.packages.items()]
    return {"outcomes": outcomes, "deps": deps}
