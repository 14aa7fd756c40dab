"""Stage timings of one process (`MPC_PROFILE=FILE`) → one JSON line appended to FILE at exit.

`with stage("lower"): …` adds the time spent inside to the stage, less the time of the stages
nested in it, so the stages of a build add up to its time. Without MPC_PROFILE a stage costs
one dictionary lookup and nothing is written. Nothing here prints or changes a build.
"""

from __future__ import annotations

import atexit
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager

_totals: dict[str, float] = {}
_stack: list[list[float]] = []  # per open stage: [start, time of its nested stages]
_registered = False


@contextmanager
def stage(name: str) -> Iterator[None]:
    if not os.environ.get("MPC_PROFILE"):
        yield
        return
    _register()
    frame = [time.perf_counter(), 0.0]
    _stack.append(frame)
    try:
        yield
    finally:
        _stack.pop()
        elapsed = time.perf_counter() - frame[0]
        _totals[name] = _totals.get(name, 0.0) + elapsed - frame[1]
        if _stack:
            _stack[-1][1] += elapsed


def _register() -> None:
    global _registered
    if not _registered:
        _registered = True
        pid = os.getpid()
        atexit.register(lambda: _write(pid))


def _write(pid: int) -> None:
    """Append this process's stages (not a forked child's, which inherits the hook)."""
    path = os.environ.get("MPC_PROFILE")
    if not path or os.getpid() != pid or not _totals:
        return
    import json

    try:
        with open(path, "a", encoding="utf-8") as f:
            f.write(json.dumps({"pid": pid, "stages": {k: round(v, 6) for k, v in _totals.items()}}) + "\n")
    except OSError:
        pass  # a profile that cannot be written never fails a build
