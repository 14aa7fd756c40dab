"""The cores this process may run on (its CPU affinity, as a container or `taskset` limits
it): how many builds `mpc run` runs side by side, and how many processes compute a build's
meshes (backends/meshes.py, backends/mesh_worker.py)."""

from __future__ import annotations

import os


def usable_cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


WORKERS = "MPC_MESH_WORKERS"
_share: int | None = None  # the cores of one of `mpc run`'s builds side by side (share_cores)


def forks_beside() -> bool:
    """Whether a build may make its plain meshes in a process beside it (backends/mesh_fork.py,
    backends/mesh_worker.py): it has two cores or more of its own (not one of `mpc run`'s
    builds), and MPC_MESH_WORKERS asks for no number of processes."""
    return _share is None and not os.environ.get(WORKERS, "").isdigit() and usable_cores() >= 2


def mesh_workers() -> int:
    """How many processes compute one build's meshes: MPC_MESH_WORKERS when it is a positive
    number, else the build's share of the cores (`mpc run -jN`), else every core this process
    may run on."""
    given = os.environ.get(WORKERS, "")
    if given.isdigit() and int(given) > 0:
        return int(given)
    return _share or usable_cores()


def share_cores(builds: int) -> None:
    """`builds` builds run side by side (`mpc run -jN`): each computes its meshes on its share
    of the cores, not on all of them (N pools of every core only fight over them)."""
    global _share
    _share = max(1, usable_cores() // max(1, builds))


def shared() -> bool:
    """Whether this build is one of `mpc run`'s side by side (share_cores)."""
    return _share is not None
