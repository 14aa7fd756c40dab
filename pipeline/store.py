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
from pathlib import Path
from typing import IO, Any

from mpc.core.files import describe, write_atomic


class BuildFolderBusy(Exception):
    """Another `mpc run` holds the build folder."""


class BuildFolderUnusable(Exception):
    """The build folder cannot be made or written (a file in the way, no permission)."""


class Store:
    """The build folder `build` and its `.mpc` state folder."""

    def __init__(self, build: Path) -> None:
        self.build = build
        self.meta = build / ".mpc"
        self._lock: IO[str] | None = None
        self._states: dict[str, tuple[dict[str, Any], str | None]] = {}  # read once a run
        self._where: dict[str, tuple[int, int]] = {}  # where an unusable state's problem is

    def output(self, model: str) -> Path:
        return self.build / model

    def staging(self, model: str) -> Path:
        return self.meta / "staging" / model

    def workdir(self, model: str) -> Path:
        return self.meta / "work" / model

    def lock(self) -> None:
        """Take the build folder for this run; BuildFolderBusy when another run has it."""
        try:
            self.meta.mkdir(parents=True, exist_ok=True)
            handle = open(self.meta / "lock", "a+")  # noqa: SIM115 (held until unlock)
        except OSError as e:
            raise BuildFolderUnusable(describe(e)) from None
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

    def state_file(self, model: str) -> Path:
        return self.meta / "state" / f"{model}.json"

    def state(self, model: str) -> dict[str, Any]:
        """The model's state from its last build, or {} when there is none or it is unusable
        (see `unusable_state`): then the model is built again."""
        data, _ = self._read_state(model)
        return data

    def unusable_state(self, model: str) -> str | None:
        """Why the model's state file cannot be used (unreadable, truncated, edited), or None
        when it is fine or absent."""
        return self._read_state(model)[1]

    def unusable_at(self, model: str) -> tuple[int, int]:
        """The line and column of what makes the state unusable (1, 1: the whole file)."""
        return self._where.get(model, (1, 1))

    def set_aside(self, model: str) -> Path | None:
        """Move the model's unusable state file to `<model>.json.unusable` beside it, where the
        next run's state does not overwrite it: the warning (W0640) quotes it and the user can
        look at it. None when it is no regular file (a link is not kept, nor quoted)."""
        path = self.state_file(model)
        aside = path.with_name(f"{path.name}.unusable")
        try:
            if not path.is_symlink() and path.is_file():
                os.replace(path, aside)
                return aside
        except OSError:
            pass
        return None

    def _read_state(self, model: str) -> tuple[dict[str, Any], str | None]:
        if model not in self._states:
            self._states[model] = self._load_state(model)
        return self._states[model]

    def _load_state(self, model: str) -> tuple[dict[str, Any], str | None]:
        from mpc.core import yaml_source as source
        from mpc.core.diagnostics import Sink

        path = self.state_file(model)
        try:
            data = _strict_json(path.read_bytes())
        except FileNotFoundError:
            if not path.is_symlink():
                return {}, None
        except (OSError, ValueError, RecursionError):
            pass
        else:
            return (data, None) if well_formed(data) else ({}, "not a state mpc writes")
        # Not JSON as mpc writes it: JSON is YAML, and the bounded loader says where and why
        sink = Sink()
        doc = source.load(path, sink)
        if doc is None:
            first = sink.diagnostics[0]
            self._where[model] = (first.span.line, first.span.col)
            return {}, f"{first.message} (line {first.span.line})"
        return (doc.data, None) if well_formed(doc.data) else ({}, "not a state mpc writes")

    def save_state(self, model: str, state: dict[str, Any]) -> None:
        self._states.pop(model, None)
        write_json(self.state_file(model), state)

    def forget_state(self, model: str) -> None:
        self._states.pop(model, None)
        self.state_file(model).unlink(missing_ok=True)

    def last_status(self) -> dict[str, Any]:
        """The last run's status.json, or {} when there is none or it cannot be read (it only
        informs the order models start in)."""
        try:
            data = json.loads((self.meta / "status.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {}
        return data if isinstance(data, dict) else {}

    def save_status(self, status: dict[str, Any]) -> Path:
        path = self.meta / "status.json"
        write_json(path, status)
        return path


def _strict_json(text: bytes) -> Any:
    """JSON as mpc writes it, read fast; ValueError (or RecursionError, for deep nesting) for
    anything else: duplicate keys, NaN, numbers of more than 50 digits."""
    def unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        out = dict(pairs)
        if len(out) != len(pairs):
            raise ValueError("a key twice")
        return out

    def bounded(digits: str) -> int:
        if len(digits) > 50:
            raise ValueError("a number too long")
        return int(digits)

    def refuse(constant: str) -> Any:
        raise ValueError(constant)

    return json.loads(text, object_pairs_hook=unique, parse_int=bounded, parse_constant=refuse)


def write_json(path: Path, data: Any) -> None:
    """Write `data` as JSON to `path` atomically."""
    write_atomic(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def well_formed(state: Any) -> bool:
    """Whether `state` has the shape `save_state` gives it, so the runner can trust its types."""
    from mpc.pipeline.status import diagnostics_from_json

    if not isinstance(state, dict):
        return False
    if not all(isinstance(state.get(k, ""), str) for k in ("pre", "fingerprint")):
        return False
    if not _deps(state.get("deps", [])):
        return False
    stages = state.get("stages", {})
    if not isinstance(stages, dict) or not all(
            isinstance(s, dict) and isinstance(s.get("fingerprint", ""), str)
            and isinstance(s.get("summary", ""), str) and isinstance(s.get("details", {}), dict)
            for s in stages.values()):
        return False
    if "stages" in state and not isinstance(state.get("fingerprint"), str):
        return False
    failure = state.get("failure")
    if failure is None:
        return True
    if not (isinstance(failure, dict) and isinstance(failure.get("pre"), str)
            and isinstance(failure.get("summary"), str) and _deps(failure.get("deps"))
            and isinstance(failure.get("diagnostics"), list)):
        return False
    try:
        diagnostics_from_json(failure["diagnostics"])
    except (KeyError, TypeError, ValueError):
        return False
    return True


def _deps(deps: Any) -> bool:
    """A list of [path, size, mtime_ns, sha256] entries (fingerprint.dep_entry)."""
    return isinstance(deps, list) and all(
        isinstance(d, list) and len(d) == 4 and isinstance(d[0], str) and isinstance(d[3], str)
        and all(isinstance(n, int) and not isinstance(n, bool) for n in d[1:3]) for d in deps)
