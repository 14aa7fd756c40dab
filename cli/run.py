"""`mpc run` and `mpc ci`: command-line arguments → a run or a CI file; diagnostics, the
status table and the exit status (0 ok, 1 a model failed, 2 bad command line, 3 a bug,
130 interrupted)."""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.core import render
from mpc.core.cores import usable_cores
from mpc.core.diagnostics import Severity, Sink, did_you_mean
from mpc.pipeline.plan import Plan, load_plan

if TYPE_CHECKING:
    from mpc.pipeline.status import RunStatus


class UsageError(Exception):
    """A command line that cannot be run (exit status 2)."""




def parse_stages(text: str) -> tuple[str, ...]:
    """The stages named on the command line, with the stages they need, in run order."""
    from mpc.pipeline.stages import KNOWN, STAGES, stages_with_needs

    names = [s.strip() for s in text.split(",") if s.strip()]
    if not names:
        raise UsageError("--stages names no stage")
    for name in names:
        if name not in KNOWN:
            raise UsageError(f"unknown stage '{name}'{did_you_mean(name, set(KNOWN))} "
                             f"(stages: {', '.join(KNOWN)})")
        if name not in STAGES:
            raise UsageError(f"stage '{name}' is not available")
    return stages_with_needs(tuple(names))


def select(plan: Plan, only: list[str]) -> tuple[str, ...]:
    """The models named by `--only`: modelnames, or definition files as the pipeline writes
    them or as paths from here."""
    out = []
    by_file = {m.definition: name for name, m in plan.models.items()}
    for word in only:
        if word in plan.models:
            out.append(word)
            continue
        match = next((n for n, m in plan.models.items() if word == m.written), None)
        match = match or by_file.get(Path(word).resolve())
        if match is None:
            near = did_you_mean(word, set(plan.models))
            raise UsageError(f"--only: no model '{word}' in '{plan.file}'{near}")
        out.append(match)
    return tuple(dict.fromkeys(out))


def _load(args: argparse.Namespace, sink: Sink) -> Plan | None:
    plan = load_plan(args.pipeline, sink, None if args.allow_root_outside else Severity.ERROR)
    render.print_diagnostics(sink.diagnostics, getattr(args, "format", "human"))
    return plan


def run(args: argparse.Namespace) -> int:
    """`mpc run PIPELINE`."""
    from mpc.pipeline import progress
    from mpc.pipeline.runner import Runner, RunOptions
    from mpc.pipeline.status import plain_table
    from mpc.pipeline.store import BuildFolderBusy, BuildFolderUnusable

    sink = Sink(werror=args.werror)
    plan = _load(args, sink)
    if plan is None:
        return 1
    try:
        stages = parse_stages(args.stages)
        only = select(plan, args.only)
        jobs = args.jobs if args.jobs is not None else usable_cores()
        if jobs < 1:
            raise UsageError("-j needs at least 1")
    except UsageError as e:
        print(f"mpc run: error: {e}", file=sys.stderr)
        return 2
    opts = RunOptions(stages=stages, only=only, jobs=jobs, force=args.force,
                      build=args.out.resolve() if args.out else None,
                      package_map={name: folder for name, folder in args.package}, werror=args.werror,
                      verify=args.verify, allow_na=args.allow_na,
                      post_processing=not args.no_post_processing)
    report = progress.reporter(args.log_format)
    runner = Runner(plan, opts, report)
    previous = signal.signal(signal.SIGTERM, _interrupt)  # a stopped run stops its workers first
    try:
        status = runner.run()
    except BuildFolderBusy as e:
        print(f"mpc run: error: another `mpc run` is using the build folder '{e}'", file=sys.stderr)
        return 1
    except BuildFolderUnusable as e:
        print(f"mpc run: error: cannot use the build folder '{runner.store.build}' ({e}); "
              "nothing was built", file=sys.stderr)
        return 1
    finally:
        signal.signal(signal.SIGTERM, previous)
        report.close()
    exit_status = status.exit_status(args.verify, args.allow_na)
    status_file = runner.store.meta / "status.json"
    if runner.status_error is not None:
        print(f"mpc run: error: cannot write the status file '{status_file}' ({runner.status_error})",
              file=sys.stderr)
        exit_status = max(exit_status, 1)
    _print_model_diagnostics(status, args.format)  # on stderr: also with JSON lines on stdout
    if args.log_format == "json":
        assert isinstance(report, progress.JsonLog)
        report.emit("end", exit_status=exit_status, counts=status.counts(), seconds=round(status.seconds, 3),
                    status=str(status_file))
        return exit_status
    if sys.stdout.isatty():
        progress.rich_table(status)
    else:
        print(plain_table(status))
    if runner.status_error is None:
        print(f"status: {status_file}")
    return exit_status


def _print_model_diagnostics(status: RunStatus, fmt: str) -> None:
    """Each model's diagnostics under its name; with `--format json`, one list for tools."""
    if fmt == "json":
        render.print_diagnostics((d for n in sorted(status.models) for d in status.models[n].diagnostics()),
                                 "json")
        return
    for name in sorted(status.models):
        diagnostics = status.models[name].diagnostics()
        if diagnostics and fmt == "human":
            print(f"── {name} ({status.models[name].definition})", file=sys.stderr)
        render.print_diagnostics(diagnostics, fmt)


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def ci(args: argparse.Namespace) -> int:
    """`mpc ci gitlab|github PIPELINE`, and `mpc ci job|summary` (what the generated jobs run)."""
    from mpc.core.version import mpc_version
    from mpc.pipeline import ci as generate
    from mpc.pipeline import ci_install

    if args.system in ("job", "summary", "review"):
        return _ci_step(args)
    sink = Sink()
    plan = _load(args, sink)
    if plan is None:
        return 1
    try:
        stages = parse_stages(args.stages)
    except UsageError as e:
        print(f"mpc ci: error: {e}", file=sys.stderr)
        return 2
    errors = [d for m in plan.models.values() for d in m.diagnostics if d.severity is Severity.ERROR]
    if errors:
        render.print_diagnostics(errors, "human")
        print("mpc ci: error: the pipeline has errors; no CI file was written", file=sys.stderr)
        return 1
    here = Path.cwd()
    build = os.path.relpath(plan.root / "build", here)
    pipeline = os.path.relpath(args.pipeline.resolve(), here)
    if build.startswith(".."):
        print(f"mpc ci: error: the build folder '{plan.root / 'build'}' is outside the current folder, "
              "where CI jobs keep their artifacts; run `mpc ci` from the project's top folder, or set "
              "the pipeline's `root` inside it", file=sys.stderr)
        return 1
    if args.install is not None:
        install: ci_install.Install | None = ci_install.given(args.install)
    elif args.image:
        install = None  # the image has mpc; the version check says so when it has another
    else:
        found = Sink()
        install = ci_install.derive(here, found)
        render.print_diagnostics(found.diagnostics, "human")
        if install is None:
            print("mpc ci: error: no CI file was written", file=sys.stderr)
            return 1
    command = " ".join(["mpc", "ci", args.system, pipeline])
    setup = generate.Setup(pipeline, build, stages, args.image, install, command, mpc_version(), here,
                           args.allow_root_outside)
    text = (generate.gitlab if args.system == "gitlab" else generate.github)(plan, setup)
    if args.output is None:
        sys.stdout.write(text)
    else:
        from mpc.core.files import describe, write_atomic

        try:
            write_atomic(args.output, text)
        except OSError as e:
            print(f"mpc ci: error: cannot write '{args.output}' ({describe(e)})", file=sys.stderr)
            return 1
        print(f"wrote {args.output}: {len(plan.models)} models, {len(plan.models) * len(stages) + 1} jobs")
    return 0


def _ci_step(args: argparse.Namespace) -> int:
    """`mpc ci job PIPELINE MODEL`, `mpc ci summary PIPELINE` (pipeline/ci_job.py) and `mpc ci
    review PIPELINE` (pipeline/ci_review.py)."""
    from mpc.pipeline import ci_job

    plan = _load(args, Sink())
    if plan is None:
        return 1
    if args.system == "review":
        from mpc.pipeline.ci_review import review

        return review(plan, args.base)
    build = args.out.resolve() if args.out else plan.root / "build"
    if args.system == "summary":
        return ci_job.summary(plan, build, args.markdown)
    try:
        stages = parse_stages(args.stages)
        [model] = select(plan, [args.model])
    except UsageError as e:
        print(f"mpc ci job: error: {e}", file=sys.stderr)
        return 2
    return ci_job.job(args, plan, model, stages, build, run)
