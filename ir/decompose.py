"""Convex decomposition (coacd) of a shape into convex parts, cached on disk.

`EditCollisions` needs the number of parts to make one collision per part, and the
emission needs each part's mesh: both read the same cache entry, keyed by the shape's
content (its file's bytes, its ops and scale) and the decomposition's settings, so a
mesh is decomposed once, however often it is used or built.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
from collections.abc import Callable

import numpy as np
import trimesh

from mpc.core.cache import cache_dir, load_entry, remove_entry, store_entry, touch_entry
from mpc.ir.geometry import Mesh

THRESHOLD = 0.05  # coacd's concavity threshold: smaller is finer (and slower)
MAX_PARTS = 16  # a bound on the parts (collisions) one mesh becomes


def _key(mesh: Mesh) -> str:
    h = hashlib.sha256(mesh.source.path.read_bytes() if mesh.source.path else b"")
    h.update(f"coacd-{THRESHOLD}-{MAX_PARTS}|{mesh.ops!r}|{mesh.scale!r}".encode())
    return h.hexdigest()


def parts(mesh: Mesh, build: Callable[[Mesh], trimesh.Trimesh]) -> list[trimesh.Trimesh]:
    """The convex parts of `mesh` (scaled, with its ops), computed once; `build` makes the
    mesh's triangles (ir/mesh_props.as_trimesh), called only when the cache has no entry.

    A damaged cache entry (core/cache.py checks its hash) is removed and computed
    again; a cache that cannot be written only costs the time of computing again.
    """
    entry = cache_dir("decompositions") / f"{_key(mesh)}.npz"
    try:
        data, bad = load_entry(entry)
        if bad is not None:
            remove_entry(entry)
    except OSError:
        data = None
    if data is not None:
        touch_entry(entry)
        arrays = np.load(io.BytesIO(data), allow_pickle=False)  # a cache entry: data, never code
        return [trimesh.Trimesh(arrays[f"v{i}"], arrays[f"f{i}"], process=False)
                for i in range(int(arrays["n"]))]
    import coacd

    coacd.set_log_level("error")
    shape = build(mesh)
    shape.merge_vertices()  # STL files repeat each vertex per face; coacd wants a connected surface
    result = coacd.run_coacd(coacd.Mesh(shape.vertices, shape.faces), threshold=THRESHOLD, seed=0,
                             max_convex_hull=MAX_PARTS)
    out = [trimesh.Trimesh(np.asarray(v), np.asarray(f), process=False) for v, f in result]
    arrays = {"n": np.array(len(out))}
    for i, m in enumerate(out):
        arrays[f"v{i}"], arrays[f"f{i}"] = m.vertices, m.faces
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    with contextlib.suppress(OSError):
        store_entry(entry, buffer.getvalue())
    return out
