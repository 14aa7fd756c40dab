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

from itertools import combinations

import numpy as np

from mpc.ir.geometry import Geometry
from mpc.ir.kinematics import links_in_root, pose_matrix
from mpc.ir.robot import Robot
from mpc.ir.tree import parent_joint

BITS = 16


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
    cannot be read. A mesh file used as it is (every robot's common case) is read without
    trimesh (core/mesh_arrays.py: trimesh's own numbers): a self-collision test then imports
    no trimesh or SciPy (half a second)."""
    from mpc.core.mesh_arrays import decode, scale_matrix, transform
    from mpc.ir.geometry import Mesh

    path = geometry.source.path if isinstance(geometry, Mesh) else None
    if isinstance(geometry, Mesh) and not geometry.ops and path is not None and path.is_file():
        try:
            arrays = decode(path.read_bytes(), path.suffix)
        except OSError:
            arrays = None  # as_trimesh says why
        if arrays is not None:
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
    """Pairs of links whose collision shapes touch or overlap at q = 0."""
    shapes = []
    X_R = links_in_root(robot)
    for name, link in robot.links.items():
        for c in link.collisions:
            shapes.append((name, coal_object(c.geometry), X_R[name] @ pose_matrix(c.origin)))
    out: set[frozenset[str]] = set()
    for (a, sa, ta), (b, sb, tb) in combinations(shapes, 2):
        if a == b or frozenset((a, b)) in out:
            continue
        if overlap(sa, ta, sb, tb):
            out.add(frozenset((a, b)))
    return out


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
