"""What C libraries print (PyBullet, urdfdom inside Pinocchio) → a string, by pointing file
descriptors 1 and 2 at a temporary file while they run; Python's own sys.stdout would miss it."""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator


@contextlib.contextmanager
def captured_fds() -> Iterator[list[str]]:
    """Everything written to fds 1 and 2 inside the block, as one string in the list."""
    out: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as f:
        os.dup2(f.fileno(), 1)
        os.dup2(f.fileno(), 2)
        try:
            yield out
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            f.seek(0)
            out.append(f.read().decode("utf-8", "replace"))
