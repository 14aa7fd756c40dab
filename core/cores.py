"""The cores this process may run on (its CPU affinity, as a container or `taskset` limits
it): how many builds `mpc run` runs side by side, and how many processes compute a build's
meshes (backends/meshes.py)."""

from __future__ import annotations

import os


def usable_cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
