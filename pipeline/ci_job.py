"""`mpc ci job` and `mpc ci summary`: what a generated CI job runs (pipeline/ci.py).

`mpc ci job PIPELINE MODEL --stages S`: `mpc run PIPELINE --only MODEL --stages S`, with
what earlier jobs left as artifacts in `<build>/.mpc/ci/<model>/`:
- their cache entries are put into `$MPC_CACHE_DIR` first, so a dependant finds the meshes
  its parents computed;
- their records decide whether the model can be built at all: a parent whose compile did
  not succeed skips it, with the reason `mpc run` gives ("derived_base 'x' failed"), and
  the job fails;
then it writes the model's record `<build>/.mpc/ci/<model>/<stage>.json` (its status, and
how many cache entries the build made and reused) and copies the cache entries it made or
used beside it, for its dependants and for the summary.

`mpc ci summary PIPELINE`: the records of every job → `<build>/.mpc/status.json` (the table
`mpc run` writes, for the whole pipeline), `<build>/.mpc/summary.md`, the table printed,
and every job's cache entries merged into `$MPC_CACHE_DIR` (which the summary job pushes).
It exits 0 when it wrote the status: the models' jobs carry their own failures.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mpc.core.cache import BESIDE, cache_dir, sidecars
from mpc.pipeline import dag
from mpc.pipeline.plan import Plan
from mpc.pipeline.status import (
    GOOD,
    ModelRecord,
    RunStatus,
    StageRecord,
    markdown_table,
    model_from_json,
    past,
    plain_table,
)

KINDS = ("meshes", "decompositions")  # the caches a job passes on (git checkouts are fetched again)


def records(build: Path) -> Path:
    return build / ".mpc" / "ci"


def latest(build: Path, model: str) -> dict[str, Any] | None:
    """The record of the model's last job (deploy, else test, else compile), or None."""
    for stage in ("deploy", "test", "compile"):
        try:
            return json.loads((records(build) / model / f"{stage}.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
    return None


def blocked(plan: Plan, build: Path, model: str, stages: tuple[str, ...]) -> str | None:
    """Why the model cannot be built in this job (a parent's compile, or the model's own in
    the job of its earlier stage, did not succeed), as `mpc run` says it; None when it can."""
    for parent in plan.models[model].parents:
        record = latest(build, parent)
        if record is None:
            return f"derived_base '{parent}' did not finish in this pipeline"
        state = record["record"]["stages"].get("compile", {}).get("state", "skipped")
        if state not in GOOD:
            return f"derived_base '{parent}' {past(state)}"
    if len(stages) < 2:
        return None
    earlier = _earlier(build, model, stages)
    if earlier is None:
        return f"its {stages[-2]} job did not finish in this pipeline"
    state = earlier["stages"].get("compile", {}).get("state", "skipped")
    return None if state in GOOD else f"compile {past(state)}"


def _earlier(build: Path, model: str, stages: tuple[str, ...]) -> dict[str, Any] | None:
    """The model's status record from its job of the stage before this job's, if any."""
    if len(stages) < 2:
        return None
    try:
        data = json.loads((records(build) / model / f"{stages[-2]}.json").read_text(encoding="utf-8"))
        return data["record"]
    except (OSError, ValueError, KeyError):
        return None


def inventory() -> dict[Path, int]:
    """Every cache entry a job passes on, with its modification time (a hit touches it)."""
    out: dict[Path, int] = {}
    for kind in KINDS:
        folder = cache_dir(kind)
        if folder.is_dir():
            for path in folder.rglob("*"):
                if path.is_file() and not path.name.startswith(".") and not path.name.endswith(BESIDE):
                    out[path] = path.stat().st_mtime_ns
    return out


def merge_caches(build: Path) -> None:
    """Put the cache entries that jobs left in `<build>/.mpc/ci/*/cache/` into the cache."""
    for kind in KINDS:
        for folder in sorted(records(build).glob(f"*/cache/{kind}")):
            for entry in sorted(folder.rglob("*")):
                target = cache_dir(kind) / entry.relative_to(folder)
                if entry.is_file() and not target.exists():
                    target.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copy2(entry, target)


def job(args: argparse.Namespace, plan: Plan, model: str, stages: tuple[str, ...], build: Path,
        run: Callable[[argparse.Namespace], int]) -> int:
    """`mpc ci job` (see the module docstring); `run` is `mpc run`'s command."""
    merge_caches(build)
    reason = blocked(plan, build, model, stages)
    if reason is not None:
        earlier = _earlier(build, model, stages)  # what the model's earlier jobs did stays
        record = model_from_json(model, earlier) if earlier else \
            ModelRecord(model, plan.models[model].written, plan.models[model].parents)
        for stage in stages:
            record.stages.setdefault(stage, StageRecord("skipped", reason, blocked=True))
        status = RunStatus(str(plan.file), stages, 1, {model: record})
        _save(build, model, stages, status.to_json()["models"][model], 0, 0)
        print(plain_table(status))
        print(f"mpc ci: {model} is not built: {reason}", file=sys.stderr)
        return 1
    before = inventory()
    code = run(argparse.Namespace(
        pipeline=args.pipeline, only=[model], stages=",".join(stages), jobs=None, force=False, out=build,
        package=args.package, werror=args.werror, verify=False, allow_na=False, log_format="text",
        format=args.format, allow_root_outside=args.allow_root_outside, no_post_processing=False))
    after = inventory()
    used = sorted(p for p, t in after.items() if before.get(p) != t)
    made = sum(p not in before for p in used)
    for path in used:
        kind = next(k for k in KINDS if path.is_relative_to(cache_dir(k)))
        target = records(build) / model / "cache" / kind / path.relative_to(cache_dir(kind))
        target.parent.mkdir(parents=True, exist_ok=True)
        for file in (path, *sidecars(path)):
            if file.is_file():
                shutil.copy2(file, target.with_name(file.name))
    try:
        status = json.loads((build / ".mpc" / "status.json").read_text(encoding="utf-8"))
        record = status["models"][model]
    except (OSError, ValueError, KeyError):
        return max(code, 1)  # `mpc run` said why
    _save(build, model, stages, record, made, len(used) - made)
    print(f"cache: {made} entries made, {len(used) - made} reused")
    return code


def _save(build: Path, model: str, stages: tuple[str, ...], record: dict[str, Any], made: int,
          reused: int) -> None:
    folder = records(build) / model
    folder.mkdir(parents=True, exist_ok=True)
    data = {"version": 1, "model": model, "stages": list(stages), "record": record,
            "cache": {"made": made, "reused": reused}}
    (folder / f"{stages[-1]}.json").write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def summary(plan: Plan, build: Path, markdown: Path | None) -> int:
    """`mpc ci summary` (see the module docstring)."""
    merge_caches(build)
    found = {name: latest(build, name) for name in plan.models}
    stages = max((tuple(r["stages"]) for r in found.values() if r), key=len, default=("compile",))
    status = RunStatus(str(plan.file), stages, 1)
    made = reused = 0
    for name in dag.order(plan.parents()):
        data = found[name]
        if data is None:
            model = plan.models[name]
            record = ModelRecord(name, model.written, model.parents)
            for stage in stages:
                record.stages[stage] = StageRecord("skipped", "its job did not run", blocked=True)
        else:
            record = model_from_json(name, data["record"])
            made, reused = made + data["cache"]["made"], reused + data["cache"]["reused"]
        status.models[name] = record
    status.seconds = sum(r.seconds for m in status.models.values() for r in m.stages.values())
    out = {**status.to_json(), "cache": {"made": made, "reused": reused}}
    table = markdown_table(status) + f"\ncache: {made} entries made, {reused} reused\n"
    try:
        (build / ".mpc").mkdir(parents=True, exist_ok=True)
        (build / ".mpc" / "status.json").write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
        (build / ".mpc" / "summary.md").write_text(table, encoding="utf-8")
        if markdown is not None:
            with markdown.open("a", encoding="utf-8") as f:
                f.write(table)
    except OSError as e:
        print(f"mpc ci: error: cannot write the status ({e.strerror or e})", file=sys.stderr)
        return 1
    print(plain_table(status))
    print(f"cache: {made} entries made, {reused} reused")
    print(f"status: {build / '.mpc' / 'status.json'}")
    return 0
