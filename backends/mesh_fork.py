"""A build's plain mesh jobs on two cores: in the build's own process and in one child forked
for them (backends/meshes.py `_compute`), each taking the next job from a queue they share.

A pool of workers (ProcessPoolExecutor) costs more to start and feed than it saves on the
plain path's tens of milliseconds (bench/README.md); one `fork` costs about 2 ms. The queue is
a pipe holding the jobs' numbers, the costliest first, written whole before the fork: each
process reads the next number (4 bytes, which a pipe hands to one reader whole) until it is
empty, so that neither waits long for the other at the end (halves fixed beforehand by their
bytes left one process 30 ms behind the other: a DAE costs more per byte than an STL).

The child makes its cache entries as the build itself would (single flight, atomic stores)
and sends back, as JSON through a second pipe, the numbers of the jobs it finished, their
problems and the SHA-256 of each entry it stored (the build then does not hash them again
when it reads them back); it ends with `os._exit` (no atexit handler, no buffer of the
build's flushed twice). A job the child did not say it finished, because it failed in any
way, the build does itself: what the child stored is found in the cache, what it did not is
computed.
"""

from __future__ import annotations

import json
import os
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TypeVar

Task = TypeVar("Task")
Problems = dict[Path, tuple[str, str]]  # cache entry → (code, problem)

_NUMBER = 4  # bytes of a job's number in the queue
_QUEUE = 65536  # bytes a pipe holds (Linux's default) before a write waits for a reader


def may_fork() -> bool:
    """Whether this process may fork a child that runs mesh code: it runs no other thread
    (whose locks the child would inherit held) and has not loaded MuJoCo (its GL context and
    threads must not be copied)."""
    return threading.active_count() == 1 and "mujoco" not in sys.modules


def beside_a_fork(tasks: Sequence[Task], costs: Sequence[float], run: Callable[[Task], Problems],
                  entries: Callable[[Task], list[Path]]) -> list[Problems]:
    """`run` of each task, here and in a forked child, the costliest first. entries: the cache
    entries a task makes (whose digests the child sends back)."""
    from mpc.core.cache import note_written, written_digest

    order = sorted(range(len(tasks)), key=lambda i: -costs[i])
    if len(order) * _NUMBER > _QUEUE:
        return [run(task) for task in tasks]
    queue, queued = os.pipe()
    os.write(queued, b"".join(i.to_bytes(_NUMBER, "little") for i in order))
    os.close(queued)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        code = 1
        try:
            os.close(read)
            done, problems, digests = [], {}, {}
            for i in _taken(queue):
                problems.update((str(entry), problem) for entry, problem in run(tasks[i]).items())
                digests.update((str(entry), digest) for entry in entries(tasks[i])
                               if (digest := written_digest(entry)) is not None)
                done.append(i)
            with os.fdopen(write, "w", encoding="utf-8") as pipe:
                json.dump({"done": done, "problems": problems, "digests": digests}, pipe)
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    results, here = [], set()
    try:
        for i in _taken(queue):
            results.append(run(tasks[i]))
            here.add(i)
    finally:
        os.close(queue)
        with os.fdopen(read, encoding="utf-8") as pipe:
            sent = pipe.read()
        _, status = os.waitpid(pid, 0)
    there: set[int] = set()
    try:
        if os.waitstatus_to_exitcode(status) != 0:
            raise ValueError("the child failed")
        answer = json.loads(sent)
        results.append({Path(entry): (code, problem)
                        for entry, (code, problem) in answer["problems"].items()})
        for entry, digest in answer["digests"].items():
            note_written(Path(entry), digest)
        there = set(answer["done"])
    except (ValueError, TypeError, KeyError, OSError):
        pass
    results.extend(run(tasks[i]) for i in range(len(tasks)) if i not in here and i not in there)
    return results


def _taken(queue: int) -> Iterator[int]:
    """The numbers of the jobs this process takes from the queue, one at a time."""
    while len(number := os.read(queue, _NUMBER)) == _NUMBER:
        yield int.from_bytes(number, "little")
