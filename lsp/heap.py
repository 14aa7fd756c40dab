"""The memory a check freed, given back to the system (glibc's `malloc_trim`).

A check of a large definition allocates and frees some megabytes outside Python's own
allocator (libxml2's parse of an input model, pydantic's validation); glibc keeps freed
chunks in the process for reuse, so the server's resident memory stays at its high-water
mark. Trimming after each check takes a fraction of a millisecond and gave back 0.8 MiB of
the 39.4 MiB of the server holding TALOS (bench/bench_lsp.py). Where the C library is not
glibc, nothing is done.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache


@cache
def _malloc_trim() -> Callable[[int], int] | None:
    import ctypes

    try:
        return ctypes.CDLL("libc.so.6").malloc_trim
    except (OSError, AttributeError):
        return None


def give_back() -> None:
    """Return the free memory at the top and inside the C heap to the system."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)
