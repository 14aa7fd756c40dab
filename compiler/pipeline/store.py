"""The build folder of a pipeline → its layout, its lock, and the state kept between runs.

    <build>/<modelname>/            each model's output (what `mpc compile` writes)
    <build>/.mpc/lock               held by the running `mpc run` (a second run waits for nothing: it stops)
    <build>/.mpc/state/<model>.json fingerprints, the files the build read, the stages that succeeded
    <build>/.mpc/status.json        the last run's status (per model and stage)
    <build>/.mpc/staging/<model>/   a build in progress; moved to <build>/<model> when it succeeded
    <build>/.mpc/work/<model>/      a scratch folder for the stages of a model

State files are written atomically (a temporary file renamed over the old one), one per
model, so a run with `--only` touches only its models and CI jobs can pass a model's
state on with its output.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import IO, Any


class BuildFolderBusy(Exception):
    """Another `mpc run` holds the build folder."""


class Store:
    """The build folder `build` and its `.mpc` state folder."""

    def __init__(self, build: Path) -> None:
        self.build = build
        self.meta = build / ".mpc"
        self._lock: IO[str] | None = None

    def output(self, model: str) -> Path:
        return self.build / model

    def staging(self, model: str) -> Path:
        return self.meta / "staging" / model

    def workdir(self, model: str) -> Path:
        return self.meta / "work" / model

    def lock(self) -> None:
        """Take the build folder for this run; BuildFolderBusy when another run has it."""
        self.meta.mkdir(parents=True, exist_ok=True)
        handle = open(self.meta / "lock", "a+")  # noqa: SIM115 (held until unlock)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            raise BuildFolderBusy(str(self.build)) from None
        self._lock = handle
        # A run that was killed leaves staging folders; nothing else uses them.
        shutil.rmtree(self.meta / "staging", ignore_errors=True)

    def unlock(self) -> None:
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def state(self, model: str) -> dict[str, Any]:
        """The model's state from its last build, or {} (none, or unreadable: then it is rebuilt)."""
        try:
            data = json.loads((self.meta / "state" / f"{model}.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {}
        return data if isinstance(data, dict) else {}

    def save_state(self, model: str, state: dict[str, Any]) -> None:
        write_json(self.meta / "state" / f"{model}.json", state)

    def save_status(self, status: dict[str, Any]) -> Path:
        path = self.meta / "status.json"
        write_json(path, status)
        return path


def write_json(path: Path, data: Any) -> None:
    """Write `data` as JSON to `path` atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(data, f, indent=2, sort_keys=True)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
