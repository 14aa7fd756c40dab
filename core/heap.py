"""Giving freed memory back to the system.

glibc keeps what a program frees in its heap for the next allocation; after a library freed a
large working set (MuJoCo compiling a model of many meshes frees three times the model's
size; a check of `mpc lsp` frees libxml2's parse and the schema's walk), the process's
resident size stays at its peak until `malloc_trim` returns the free pages.
"""

from __future__ import annotations

import ctypes
import functools


@functools.cache
def _trim() -> ctypes._CFuncPtr | None:  # type: ignore[name-defined]
    # glibc by its soname: `ctypes.util.find_library` would run `ldconfig -p` to find it
    try:
        return ctypes.CDLL("libc.so.6").malloc_trim
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to give back this way
        return None


def give_back() -> None:
    """Return the heap's free pages to the system, where the C library can."""
    trim = _trim()
    if trim is not None:
        trim(0)
