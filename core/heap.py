"""The C heap of this process: giving freed memory back to the system, or keeping it.

glibc keeps what a program frees in its heap for the next allocation; after a library freed a
large working set (MuJoCo compiling a model of many meshes frees three times the model's
size; a check of `mpc lsp` frees libxml2's parse and the schema's walk), the process's
resident size stays at its peak until `malloc_trim` returns the free pages (`give_back`).

A build wants the opposite (`keep_freed`). glibc maps each allocation of 128 KiB or more on
its own and unmaps it when it is freed, and returns the top of the heap once 128 KiB of it lie
free (thresholds it raises only as far as the largest block freed so far). A mesh job
allocates and frees megabytes at a time (a DAE's tree and number arrays, the triangles, the
STL's bytes), so each job's memory was new to the process: the kernel zeroes every page of it
and maps it at the first touch, a page fault each. UR5's upperarm.dae took 2,200–2,500 faults
and 5 of its 27 ms each time it was derived (bench/README.md, 2026-11-28). A build lives for
seconds: it keeps what it frees and its later jobs reuse those pages. Its peak is what it
was; the memory is only not given back before the process ends.
"""

from __future__ import annotations

import ctypes
import functools

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt's parameters (glibc's malloc.h)
MAPPED_ABOVE = 64 << 20  # a block this large still gets a mapping of its own, unmapped when freed
KEPT = 256 << 20  # more free memory than this at the heap's top is given back


@functools.cache
def _libc() -> ctypes.CDLL | None:
    # glibc by its soname: `ctypes.util.find_library` would run `ldconfig -p` to find it
    try:
        return ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc (musl, macOS): nothing to give back or keep this way
        return None


def give_back() -> None:
    """Return the heap's free pages to the system, where the C library can."""
    trim = getattr(_libc(), "malloc_trim", None)
    if trim is not None:
        trim(0)


def keep_freed() -> None:
    """Keep what this process frees for its next allocations, where the C library can: for a
    build's process (`mpc compile`, `mpc run`, the mesh worker), not a long-lived one."""
    mallopt = getattr(_libc(), "mallopt", None)
    if mallopt is not None:
        mallopt(_M_MMAP_THRESHOLD, MAPPED_ABOVE)
        mallopt(_M_TRIM_THRESHOLD, KEPT)
