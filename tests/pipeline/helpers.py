"""Running `mpc run` as users do (a subprocess) and reading what it reports."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.mpc_command import mpc_process

ROOT = Path(__file__).resolve().parents[2]
FLEET = ROOT / "examples" / "fleet"


@dataclass
class Run:
    """One `mpc run --log-format json`: exit status, events, stderr, and status.json."""

    returncode: int
    events: list[dict[str, Any]]
    stderr: str
    status: dict[str, Any]

    def started(self) -> list[str]:
        return [e["model"] for e in self.events if e["event"] == "start"]

    def state(self, model: str, stage: str = "compile") -> str:
        return self.status["models"][model]["stages"][stage]["state"]

    def states(self, stage: str = "compile") -> dict[str, str]:
        return {m: self.state(m, stage) for m in self.status["models"]}


def env(cache: Path) -> dict[str, str]:
    return {**os.environ, "MPC_CACHE_DIR": str(cache)}


def mpc(*args: str | Path, cwd: Path | None = None, cache: Path | None = None,
        environ: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """`mpc ARGS` as a process; `environ`: variables set (or, when "", removed) for it."""
    changed = env(cache) if cache else dict(os.environ)
    for name, value in (environ or {}).items():
        if value:
            changed[name] = value
        else:
            changed.pop(name, None)
    return mpc_process(*args, cwd=cwd, env=changed if cache or environ else None)


def run_json(pipeline: Path, *args: str, cache: Path, cwd: Path | None = None,
             environ: dict[str, str] | None = None) -> Run:
    done = mpc("run", pipeline, "--log-format", "json", *args, cwd=cwd, cache=cache, environ=environ)
    events = [json.loads(line) for line in done.stdout.splitlines()]
    end = events[-1]
    assert end["event"] == "end", done.stdout + done.stderr
    status = json.loads(Path(end["status"]).read_text())
    return Run(done.returncode, events, done.stderr, status)


def copy_fleet(to: Path) -> Path:
    shutil.copytree(FLEET, to)
    return to / "pipeline.yml"
