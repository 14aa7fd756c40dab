"""Work a build does while its mesh worker starts on the meshes it was just given.

At its first mesh stage a build gives every job to the worker (backends/mesh_worker.py), which
makes them the costliest first, and then makes them itself the cheapest first, until they
meet. Whatever else the build must do, and could do before, costs the whole build its time
when it comes after the meshes; done first, while the worker has jobs, it costs about half of
it: the worker makes that much more of the meshes. So work that needs the robot but no mesh
(keeping the build's model, compiler/build_cache.py) is put `later` here and done at that
moment (`now`), or where it was needed if no mesh stage came.
"""

from __future__ import annotations

from collections.abc import Callable

_pending: list[Callable[[], object]] = []


def later(work: Callable[[], object]) -> None:
    """Do `work` at the next `now`."""
    _pending.append(work)


def now() -> None:
    """Do what was put `later`, in order."""
    while _pending:
        _pending.pop(0)()


def drop() -> None:
    """Forget what was put `later` (the build is over)."""
    _pending.clear()
