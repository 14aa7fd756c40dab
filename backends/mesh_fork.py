"""A build's plain mesh jobs on two cores: half in the build's own process, half in one child
forked for them (backends/meshes.py `_compute`).

A pool of workers (ProcessPoolExecutor) costs more to start and feed than it saves on the
plain path's tens of milliseconds (bench/README.md); one `fork` costs about 2 ms. The child makes
its cache entries as the build itself would (single flight, atomic stores) and sends back only
its problems, as JSON through a pipe, then ends with `os._exit` (no atexit handler, no buffer
of the build's flushed twice). When the child fails in any way, the build does its half
itself: what the child stored is found in the cache, what it did not is computed.
"""

from __future__ import annotations

import json
import os
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

Task = TypeVar("Task")
Problems = dict[Path, tuple[str, str]]  # cache entry → (code, problem)


def may_fork() -> bool:
    """Whether this process may fork a child that runs mesh code: it runs no other thread
    (whose locks the child would inherit held) and has not loaded MuJoCo (its GL context and
    threads must not be copied)."""
    return threading.active_count() == 1 and "mujoco" not in sys.modules


def halves(tasks: Sequence[Task], sizes: Sequence[int]) -> tuple[list[Task], list[Task]]:
    """The tasks in two halves of about the same bytes, the largest first into the lighter."""
    mine: list[Task] = []
    theirs: list[Task] = []
    weight = [0, 0]
    for i in sorted(range(len(tasks)), key=lambda i: -sizes[i]):
        half = 0 if weight[0] <= weight[1] else 1
        (mine, theirs)[half].append(tasks[i])
        weight[half] += sizes[i]
    return mine, theirs


def beside_a_fork(tasks: Sequence[Task], sizes: Sequence[int],
                  run: Callable[[Task], Problems]) -> list[Problems]:
    """`run` of each task: about half of the bytes (`sizes`) in a forked child, the rest here."""
    mine, theirs = halves(tasks, sizes)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        code = 1
        try:
            os.close(read)
            found = {str(entry): problem for task in theirs for entry, problem in run(task).items()}
            with os.fdopen(write, "w", encoding="utf-8") as pipe:
                json.dump(found, pipe)
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    try:
        results = [run(task) for task in mine]
    finally:
        with os.fdopen(read, encoding="utf-8") as pipe:
            sent = pipe.read()
        _, status = os.waitpid(pid, 0)
    try:
        if os.waitstatus_to_exitcode(status) != 0:
            raise ValueError("the child failed")
        found = json.loads(sent)
        results.append({Path(entry): (code, problem) for entry, (code, problem) in found.items()})
    except (ValueError, TypeError):
        results.extend(run(task) for task in theirs)
    return results
