"""What a shape is made of, as a digest: the key of the caches that keep what is computed from
collision shapes (checks/shape_figures.py: a shape's figures; ir/bitmask.py: which links touch).

A mesh's key is its file's bytes (core/cache.py `file_digest`: remembered by the file's
identity, so a warm key reads no mesh), its suffix, scale and ops; a primitive's, its
dimensions. A mesh without its file, or one joined from other shapes (`JoinShapes`: more
files than its own), has none: what is computed from it is not kept.
"""

from __future__ import annotations

import hashlib

from mpc.ir.geometry import Geometry, JoinShapes, Mesh


def shape_key(geometry: Geometry) -> str | None:
    if not isinstance(geometry, Mesh):
        return hashlib.sha256(repr(geometry).encode()).hexdigest()
    path = geometry.source.path
    if path is None or any(isinstance(op, JoinShapes) for op in geometry.ops):
        return None
    from mpc.core.cache import file_digest

    try:
        digest = file_digest(path)
    except OSError:
        return None  # unreadable: computing it says so
    text = f"{digest}|{path.suffix.lower()}|{geometry.scale!r}|{geometry.ops!r}"
    return hashlib.sha256(text.encode()).hexdigest()
