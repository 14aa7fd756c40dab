"""A process started as a cold build starts, which makes the build's plain mesh jobs beside it.

A cold build's meshes cost more than half of what its inputs, ops and writers cost, and all of
that runs on one core before the mesh stage starts. The worker is started as the build starts
when no build of the definition is kept (its first, or the cache was emptied), else before
the front end (`start`: a fresh interpreter running this module); it imports numpy and the
plain mesh path while the build opens its cache and imports and checks the definition (this
module imports nothing of the IR until then), and is given jobs as soon as they are
known: those the input models give as they are read (`offer` after the front end: their meshes
in the exports' formats), then, at the mesh stage, the build's own (those of the meshes the ops
changed). It makes them the costliest first; the build makes its own the cheapest first. Each
job is made once across the two processes by the cache's single flight (core/cache.py): one
that finds an entry locked waits, then uses what the other stored. A job given ahead of time
that the ops made unneeded (a mesh mirrored later) is work of the other core only, and its
entry is an entry of the cache like any.

The jobs go through a pipe, read by a thread of the worker as they come (the build never waits
for a busy worker to read them); the worker sends back, through another pipe, the SHA-256 of
each entry it stored, so that the build does not hash it again when it reads it back. `stop`
ends the worker when the build's meshes are made, whatever it is doing (a job it was given
that the build no longer needs: a write it had begun leaves no file, core/files.py
`write_atomic`). A worker that dies or is killed costs only its jobs, which the build then
makes itself; one whose build dies is ended by the kernel (PR_SET_PDEATHSIG).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # not imported before the worker starts: it would load the IR first
    from mpc.backends.plain_meshes import Job

_LENGTH = 4  # bytes of a message's length, before its pickle

_pid = 0  # the worker's, while there is one
_jobs = -1  # the pipe the build writes jobs into
_digests = -1  # the pipe the worker writes "entry\tdigest" lines into
_offered: set[Path] = set()  # the cache entries given to the worker
_read = b""  # what the build read of `_digests` beyond the last whole line


def start() -> None:
    """Start the worker, when there is none. The build asks for it when it has two cores or
    more of its own (core/cores.py `forks_beside`).

    A fresh interpreter, not a fork: a fork of the build shares its memory until either writes
    a page, and the build's front end, which writes to most of its pages, then copied them one
    by one (about 7 ms of a cold build's front end; A/B 0.92 of the whole build)."""
    global _pid, _jobs, _digests
    if _pid:
        return
    jobs, _jobs = os.pipe()
    _digests, digests = os.pipe()
    actions = [(os.POSIX_SPAWN_DUP2, jobs, _JOBS_FD), (os.POSIX_SPAWN_DUP2, digests, _DIGESTS_FD),
               *((os.POSIX_SPAWN_OPEN, fd, os.devnull, os.O_RDWR, 0) for fd in (0, 1, 2))]
    try:
        _pid = os.posix_spawn(sys.executable, [sys.executable, "-m", __name__], os.environ,
                              file_actions=actions)
    except OSError:  # the build makes its meshes itself
        _pid = 0
        for fd in (_jobs, _digests):
            os.close(fd)
    finally:
        os.close(jobs)
        os.close(digests)
    if _pid:
        os.set_blocking(_digests, False)
    _offered.clear()


_JOBS_FD, _DIGESTS_FD = 3, 4  # the worker's ends of the two pipes


def active() -> bool:
    return _pid != 0


def offer(tasks: Sequence[tuple[list[Job], float]]) -> None:
    """Give the worker the tasks (the jobs of one source each, and their cost) it was not given."""
    new = [(jobs, cost) for jobs, cost in tasks if not all(dest in _offered for _, _, dest in jobs)]
    if not _pid or not new:
        return
    message = pickle.dumps(new)
    try:
        os.write(_jobs, len(message).to_bytes(_LENGTH, "little") + message)
    except OSError:  # the worker is gone: the build makes them
        stop()
        return
    _offered.update(dest for jobs, _ in new for _, _, dest in jobs)


def note_digests() -> None:
    """Note the digest of each entry the worker stored (core/cache.py `note_written`)."""
    global _read
    from mpc.core.cache import note_written

    if not _pid:
        return
    with contextlib.suppress(BlockingIOError, OSError):
        while chunk := os.read(_digests, 65536):
            _read += chunk
    *lines, _read = _read.split(b"\n")
    for line in lines:
        entry, _, digest = line.decode("utf-8", "surrogateescape").partition("\t")
        with contextlib.suppress(OSError):  # gone since: read back, it is hashed
            note_written(Path(entry), digest)


def stop() -> None:
    """End the worker and wait for it."""
    global _pid, _read
    if not _pid:
        return
    pid, _pid, _read = _pid, 0, b""
    for fd in (_jobs, _digests):
        with contextlib.suppress(OSError):
            os.close(fd)
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGTERM)
    with contextlib.suppress(ChildProcessError):
        os.waitpid(pid, 0)


# -- the worker's side ---------------------------------------------------------------------

class _Stop(BaseException):
    """SIGTERM: the build has ended."""


def _stopped(signum: int, frame: Any) -> None:
    raise _Stop


def _serve(jobs: int, digests: int) -> None:
    """Make the jobs that come through `jobs`, the costliest first, until the build ends."""
    signal.signal(signal.SIGTERM, _stopped)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the build's to handle
    _die_with_parent()
    os.set_blocking(digests, False)  # a line at a time: whole, or not at all when the pipe is full
    pending: list[tuple[list[Job], float]] = []
    arrived = threading.Condition()
    ended = False

    def receive() -> None:
        nonlocal ended
        with os.fdopen(jobs, "rb") as pipe:
            while len(head := pipe.read(_LENGTH)) == _LENGTH:
                tasks = pickle.loads(pipe.read(int.from_bytes(head, "little")))  # the build's own
                with arrived:
                    pending.extend(tasks)
                    pending.sort(key=lambda task: task[1])
                    arrived.notify()
        with arrived:
            ended = True
            arrived.notify()

    threading.Thread(target=receive, daemon=True).start()
    from mpc.core.heap import keep_freed

    keep_freed()  # what a job frees, the next one reuses (core/heap.py)
    import lxml.etree  # noqa: F401  # while the build checks its definition: what a job needs
    import numpy  # noqa: F401

    from mpc.backends.plain_meshes import materialise
    from mpc.core.cache import written_digest
    from mpc.core.mesh_arrays import decode  # noqa: F401

    try:
        while True:
            with arrived:
                while not pending and not ended:
                    arrived.wait()
                if not pending:
                    return
                jobs_of_one, _ = pending.pop()
            materialise(jobs_of_one)
            lines = "".join(f"{dest}\t{digest}\n" for _, _, dest in jobs_of_one
                            if (digest := written_digest(dest)) is not None)
            with contextlib.suppress(OSError):  # a full pipe: the build hashes what it reads
                os.write(digests, lines.encode("utf-8", "surrogateescape"))
    except _Stop:
        return


def _die_with_parent() -> None:
    """SIGTERM when the build's process ends, whatever ends it (Linux's PR_SET_PDEATHSIG)."""
    with contextlib.suppress(OSError, AttributeError):
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


if __name__ == "__main__":
    try:
        _serve(_JOBS_FD, _DIGESTS_FD)
    finally:
        os._exit(0)
