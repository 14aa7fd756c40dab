"""Self-collision bitmasks: which links may collide, and 16-bit masks that say so.

Two collisions collide when their bitmasks share a bit (MARS's and Phobos's rule). Links
never collide with (Phobos's rules): their parent; ancestors above it while the joints
in between have a zero translation (only rotation: they share the joint's centre); and
links whose collision shapes touch or overlap at the zero configuration (tested with
coal). `never` and `always` override pairs. Each bit is then a set of links that may all
collide with each other; bits are added greedily until every allowed pair shares one,
16 at most — a pair left over cannot collide (the safe side) and is reported.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from itertools import combinations
from pathlib import Path

import numpy as np

from mpc.ir.geometry import Geometry
from mpc.ir.kinematics import links_in_root, pose_matrix
from mpc.ir.robot import Robot
from mpc.ir.tree import parent_joint

BITS = 16
TOUCHING_VERSION = "1"  # changes when what counts as touching changes: old entries go unused


Triangles = tuple[np.ndarray, np.ndarray]  # vertices (n, 3), triangles (m, 3)


def coal_object(geometry: Geometry, triangles: Triangles | None = None) -> object:
    """The shape as a coal collision object in its own frame (a mesh: a BVH of its triangles;
    `triangles`: the mesh's (`mesh_triangles`), when the caller read them already)."""
    import coal

    from mpc.ir.geometry import Box, Cylinder, Sphere

    if isinstance(geometry, Box):
        return coal.Box(*geometry.size)
    if isinstance(geometry, Cylinder):
        return coal.Cylinder(geometry.radius, geometry.length)
    if isinstance(geometry, Sphere):
        return coal.Sphere(geometry.radius)
    vertices, faces = triangles if triangles is not None else mesh_triangles(geometry)
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(faces), len(vertices))
    model.addVertices(np.asarray(vertices, dtype=float))
    model.addTriangles(np.asarray(faces, dtype=np.int64))
    model.endModel()
    return model


def mesh_triangles(geometry: Geometry) -> Triangles:
    """The vertices and triangles of a mesh shape, scaled, with its ops; MeshError when its file
    cannot be read. A mesh file used as it is, mirrored or scaled (ir/mesh_plain.py: every
    robot's common cases) is read without trimesh (core/mesh_arrays.py: trimesh's own numbers):
    a self-collision test then imports no trimesh or SciPy (half a second)."""
    from mpc.core.mesh_arrays import decode, scale_matrix, transform
    from mpc.ir.geometry import Mesh
    from mpc.ir.mesh_plain import applied, is_plain

    path = geometry.source.path if isinstance(geometry, Mesh) else None
    if isinstance(geometry, Mesh) and is_plain(geometry.ops) and path is not None and path.is_file():
        try:
            arrays = decode(path.read_bytes(), path.suffix)
        except OSError:
            arrays = None  # as_trimesh says why
        if arrays is not None:
            arrays = applied(arrays, geometry.ops)
            if geometry.scale is not None:
                arrays = transform(arrays, scale_matrix(np.asarray(geometry.scale)))
            return arrays.vertices, arrays.faces
    from mpc.ir.mesh_props import as_trimesh

    mesh = as_trimesh(geometry)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def overlap(a: object, X_a: np.ndarray, b: object, X_b: np.ndarray) -> bool:
    """Whether two coal objects (coal_object) at the poses X_a, X_b (4×4) touch or overlap."""
    import coal

    return bool(coal.collide(a, coal.Transform3s(X_a[:3, :3], X_a[:3, 3]), b,
                             coal.Transform3s(X_b[:3, :3], X_b[:3, 3]), coal.CollisionRequest(),
                             coal.CollisionResult()))


def touching(robot: Robot) -> set[frozenset[str]]:
    """Pairs of links whose collision shapes touch or overlap at q = 0; kept in the cache
    (`touching/`) by the shapes (ir/shape_keys.py) and their places, so that the next build or
    test of the same robot (`auto_bitmask` again) tests no pair."""
    X_R = links_in_root(robot)
    placed = [(name, c.geometry, X_R[name] @ pose_matrix(c.origin))
              for name, link in robot.links.items() for c in link.collisions]
    entry = _touching_entry(placed)
    if entry is not None:
        from mpc.core.cache import load_entry

        data, _ = load_entry(entry)
        if data is not None:
            with contextlib.suppress(ValueError, TypeError):
                return {frozenset(pair) for pair in json.loads(data) if len(pair) == 2}
    shapes = [(name, coal_object(g), X) for name, g, X in placed]
    out: set[frozenset[str]] = set()
    for (a, sa, ta), (b, sb, tb) in combinations(shapes, 2):
        if a == b or frozenset((a, b)) in out:
            continue
        if overlap(sa, ta, sb, tb):
            out.add(frozenset((a, b)))
    if entry is not None:
        from mpc.core.cache import store_entry

        with contextlib.suppress(OSError):  # a read-only cache: computed each time
            store_entry(entry, json.dumps(sorted(sorted(p) for p in out)).encode())
    return out


def _touching_entry(placed: list[tuple[str, Geometry, np.ndarray]]) -> Path | None:
    """The cache entry of the touching pairs of these shapes at these places; None when a
    shape has no key."""
    from mpc.core.cache import cache_dir
    from mpc.ir.shape_keys import shape_key

    h = hashlib.sha256(f"touching {TOUCHING_VERSION}".encode())
    for name, geometry, X in placed:
        key = shape_key(geometry)
        if key is None:
            return None
        h.update(f"|{name}|{key}|".encode() + np.ascontiguousarray(X, dtype=np.float64).tobytes())
    digest = h.hexdigest()
    return cache_dir("touching") / f"{digest}.json"


def never_colliding(robot: Robot) -> set[frozenset[str]]:
    """Pairs of links that the kinematic rules keep apart (parents, rotation-only ancestors)."""
    parents = parent_joint(robot)
    out: set[frozenset[str]] = set()
    for link in robot.links:
        joint = parents.get(link)
        while joint is not None:
            out.add(frozenset((link, joint.parent)))
            if joint.origin is not None and any(joint.origin.xyz):
                break
            joint = parents.get(joint.parent)
    return out


def assign(links: list[str], allowed: set[frozenset[str]]) -> tuple[dict[str, int], set[frozenset[str]]]:
    """Bitmasks such that allowed pairs share a bit and no other pair does; the allowed
    pairs that 16 bits could not cover."""
    uncovered = set(allowed)
    masks = dict.fromkeys(links, 0)
    for bit in range(BITS):
        if not uncovered:
            break
        a, b = sorted(min(uncovered, key=lambda p: tuple(sorted(p))))
        clique = [a, b]
        candidates = sorted(set(links) - {a, b})
        # Grow the clique with links allowed against all its members, most new pairs first.
        while True:
            fits = [c for c in candidates if all(frozenset((c, m)) in allowed for m in clique)]
            if not fits:
                break
            best = max(fits, key=lambda c: (sum(frozenset((c, m)) in uncovered for m in clique),
                                            -links.index(c)))
            clique.append(best)
            candidates.remove(best)
        for m in clique:
            masks[m] |= 1 << bit
        uncovered -= {frozenset(p) for p in combinations(clique, 2)}
    return masks, uncovered
