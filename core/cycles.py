"""Python's cyclic garbage collector paused around work that makes many objects and no garbage
cycles (a model read, a check of the language server).

Such work allocates tens of thousands of objects, freed by reference counting or kept as the
result; each 700 allocations the collector would scan the young ones, and now and then
everything the process holds, to find nothing. A TALOS URDF read spends 7% of its time so.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator


@contextlib.contextmanager
def paused_cycle_collection() -> Iterator[None]:
    """No cyclic collection inside; afterwards the collector is as it was (paused ones nest)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
