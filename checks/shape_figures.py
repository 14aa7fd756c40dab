"""What physical_validity needs of one collision shape, computed once for its mesh ever: the
bounds of the shape in its own frame, and whether it is a closed solid, with its volume and the
principal moments of its inertia at unit density (ir/solids.py).

The figures of a mesh are kept in the cache (core/cache.py, `shapes/`), keyed by what the
shape is made of (ir/shape_keys.py: the file's bytes, the ops and the scale): a later test of
the same meshes (the next commit's CI job) reads no mesh and imports neither trimesh nor
manifold3d, half a second of `mpc test`. A shape without a key is computed each time. An
entry is JSON numbers, read back through its hash (`load_entry`); a damaged one is computed
again. Figures are pose-free: a shape moved or turned keeps its volume and principal moments.
"""

from __future__ import annotations

import contextlib
import hashlib
import json

import numpy as np

from mpc.core.record import record
from mpc.ir.geometry import Geometry, Mesh
from mpc.ir.shape_keys import shape_key

VERSION = "1"  # changes when what is computed changes, so that old entries go unused
Vec3 = tuple[float, float, float]


@record
class Figures:
    """bounds: (least, greatest) corner in the shape's frame, None when its mesh cannot be read;
    closed: a closed solid (volume and moments mean something only then)."""

    bounds: tuple[Vec3, Vec3] | None
    closed: bool
    volume: float
    moments: Vec3


def figures(geometry: Geometry) -> Figures:
    """The shape's figures, from the cache when it has them."""
    key = _key(geometry)
    if key is None:
        return _computed(geometry)
    from mpc.core.cache import cache_dir, load_entry, store_entry

    entry = cache_dir("shapes") / f"{key}.json"
    data, _ = load_entry(entry)
    if data is not None:
        try:
            return _decoded(json.loads(data))
        except (ValueError, TypeError, KeyError):
            pass  # not what this version writes: computed again
    found = _computed(geometry)
    with contextlib.suppress(OSError):  # a read-only cache still serves what it has
        store_entry(entry, json.dumps(_encoded(found)).encode())
    return found


def _key(geometry: Geometry) -> str | None:
    shape = shape_key(geometry)
    return None if shape is None else hashlib.sha256(f"{VERSION}|{shape}".encode()).hexdigest()


def _computed(geometry: Geometry) -> Figures:
    from mpc.ir.inertia import principal
    from mpc.ir.mesh_props import MeshError, as_trimesh, solid

    bounds = None
    if isinstance(geometry, Mesh):
        try:
            lo, hi = as_trimesh(geometry).bounds
            bounds = (_vec(lo), _vec(hi))
        except MeshError:
            pass
    try:
        shape = solid(geometry)
    except MeshError:
        return Figures(bounds, False, 0.0, (0.0, 0.0, 0.0))
    moments = principal(shape.props) if shape.props.mass > 0 else np.zeros(3)
    return Figures(bounds, shape.closed, float(shape.props.mass), _vec(moments))


def _vec(values: object) -> Vec3:
    x, y, z = (float(v) for v in values)  # type: ignore[attr-defined]
    return (x, y, z)


def _encoded(f: Figures) -> dict[str, object]:
    return {"bounds": f.bounds, "closed": f.closed, "volume": f.volume, "moments": f.moments}


def _decoded(d: dict[str, object]) -> Figures:
    bounds = d["bounds"]
    lo_hi = None if bounds is None else (_vec(bounds[0]), _vec(bounds[1]))  # type: ignore[index]
    return Figures(lo_hi, bool(d["closed"]), float(d["volume"]), _vec(d["moments"]))  # type: ignore[arg-type]
