"""Shapes → solids (manifold3d): closed meshes, safe repairs, unions; volume, centre of volume
and inertia tensor at unit density. It reports nothing itself: what it repaired or replaced
comes back as sentences (`Solid.notes`) that the callers turn into diagnostics.

A mesh is a solid when, with duplicate vertices merged, it is an oriented closed 2-manifold
(manifold3d accepts it). Safe repairs: merging duplicate vertices, dropping degenerate and
repeated triangles, making the winding consistent and outward, and closing holes of three or
four edges. Anything else is not repaired: the shape's convex hull stands in for it, with a
note naming the mesh. Primitives are exact (analytic) as long as they do not overlap.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import field

import numpy as np
import trimesh
from manifold3d import Error, Manifold, Mesh64, OpType

from mpc.core.record import record
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere
from mpc.ir.inertia import Body, combine, placed

SEGMENTS = 128  # circle segments of a cylinder or sphere that overlaps another shape
RELATIVE = 1e-9  # union volume = sum of the parts' within this: the parts do not overlap
HULL, REPAIRED = "W0580", "W0581"  # the codes of the notes
Note = tuple[str, str]  # (diagnostic code, sentence)


def of_trimesh(mesh: trimesh.Trimesh) -> Body:
    """Exact props of a closed, outward-oriented triangle mesh (divergence theorem)."""
    with np.errstate(invalid="ignore", divide="ignore"):  # no volume: its centre is 0 / 0
        props = trimesh.triangles.mass_properties(mesh.triangles, density=1.0, skip_inertia=False) \
            if len(mesh.faces) else {"volume": 0.0}
    if not props["volume"] > 0:
        return Body(0.0, np.zeros(3), np.zeros((3, 3)))
    return Body(float(props["volume"]), np.asarray(props["center_mass"], dtype=float),
                np.asarray(props["inertia"], dtype=float))


def of_primitive(shape: Box | Cylinder | Sphere) -> Body:
    """Exact props of a box, cylinder (along z) or sphere centred at its origin."""
    if isinstance(shape, Box):
        a, b, c = shape.size
        v = a * b * c
        diag = (v / 12 * (b * b + c * c), v / 12 * (a * a + c * c), v / 12 * (a * a + b * b))
    elif isinstance(shape, Cylinder):
        r, h = shape.radius, shape.length
        v = np.pi * r * r * h
        side = v / 12 * (3 * r * r + h * h)
        diag = (side, side, v * r * r / 2)
    else:
        r = shape.radius
        v = 4 / 3 * np.pi * r**3
        diag = (2 / 5 * v * r * r,) * 3
    return Body(float(v), np.zeros(3), np.diag(diag))


def manifold_of_trimesh(mesh: trimesh.Trimesh) -> Manifold:
    """The manifold of a triangle mesh as it is (empty, with a status, if it is no solid)."""
    return Manifold(Mesh64(np.ascontiguousarray(mesh.vertices, dtype=np.float64),
                           np.ascontiguousarray(mesh.faces, dtype=np.uint64)))


def to_trimesh(solid: Manifold) -> trimesh.Trimesh:
    out = solid.to_mesh64()
    return trimesh.Trimesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts), process=False)


def _is_solid(m: Manifold) -> bool:
    return m.status() == Error.NoError and not m.is_empty() and m.volume() > 0


def closed(mesh: trimesh.Trimesh) -> bool:
    """Whether the mesh, with duplicate vertices merged, is a closed oriented solid."""
    merged = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)
    return _is_solid(manifold_of_trimesh(merged))


def solid_of_trimesh(mesh: trimesh.Trimesh, name: str) -> tuple[Manifold, list[Note]]:
    """The mesh as a solid: as it is, else safely repaired (W0581), else its convex hull
    (W0580); the notes say which (none for merging duplicate vertices, which every STL file
    needs)."""
    work = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)  # merges duplicate vertices
    solid = manifold_of_trimesh(work)
    if _is_solid(solid):
        return solid, []
    if work.is_watertight and work.is_winding_consistent and _signed_volume(work) < 0:
        work.invert()  # closed but inside out (e.g. a reflection written without reversing)
        solid = manifold_of_trimesh(work)
        if _is_solid(solid):
            return solid, []
    open_edges = _open_edges(work)
    work.update_faces(work.nondegenerate_faces())
    work.update_faces(work.unique_faces())
    with np.errstate(invalid="ignore", divide="ignore"):  # a flat mesh's centre is 0 / 0
        trimesh.repair.fix_winding(work)
        trimesh.repair.fill_holes(work)  # only holes of three or four edges
        trimesh.repair.fix_inversion(work)
    solid = manifold_of_trimesh(work)
    if _is_solid(solid):
        what = f"closed {open_edges} open edges" if open_edges else "fixed its triangle winding"
        return solid, [(REPAIRED, f"mesh '{name}' was not a closed solid; repaired ({what})")]
    hull = Manifold.hull_points(np.ascontiguousarray(mesh.vertices, dtype=np.float64))
    return hull, [(HULL, f"mesh '{name}' is not a closed solid ({_open_edges(work)} open edges after "
                   "merging vertices and closing small holes); its convex hull stands in for it")]


def _signed_volume(mesh: trimesh.Trimesh) -> float:
    """The volume the triangles enclose, negative when they face inwards (trimesh's
    `volume` would also divide by it for a centre, and warn when it is 0)."""
    a, b, c = (mesh.triangles[:, i] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _open_edges(mesh: trimesh.Trimesh) -> int:
    """Edges used by one triangle only."""
    edges = mesh.edges_sorted
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.sum(counts == 1))


def mesh_name(mesh: Mesh) -> str:
    return mesh.source.uri


@record(frozen=False)
class Solid:
    """A shape as a solid in its own frame: props (a Body whose mass is the volume: density 1;
    exact for primitives), its manifold, and notes on repairs or the convex-hull fallback
    (`closed` False then)."""

    props: Body
    manifold: Manifold
    closed: bool = True
    notes: list[Note] = field(default_factory=list)


def solid_of_primitive(geometry: Box | Cylinder | Sphere) -> Solid:
    """A primitive as a solid: exact props."""
    if isinstance(geometry, Box):
        return Solid(of_primitive(geometry), Manifold.cube(geometry.size, True))
    if isinstance(geometry, Cylinder):
        m = Manifold.cylinder(geometry.length, geometry.radius, geometry.radius, SEGMENTS, True)
        return Solid(of_primitive(geometry), m)
    return Solid(of_primitive(geometry), Manifold.sphere(geometry.radius, SEGMENTS))


def solid_of_mesh(mesh: trimesh.Trimesh, name: str) -> Solid:
    """The triangles of the mesh called `name` (with its ops and scale applied) as a solid;
    ValueError when its vertices are not finite numbers."""
    if not np.isfinite(mesh.vertices).all():
        raise ValueError(f"mesh '{name}' has vertices that are not finite numbers")
    if len(mesh.faces) == 0:
        empty = Body(0.0, np.zeros(3), np.zeros((3, 3)))
        return Solid(empty, Manifold(), closed=False,
                     notes=[(HULL, f"mesh '{name}' has no triangles: it adds no volume")])
    m, notes = solid_of_trimesh(mesh, name)
    return Solid(of_trimesh(to_trimesh(m)), m, closed=all(code != HULL for code, _ in notes), notes=notes)


def union(parts: Sequence[tuple[Solid, np.ndarray]]) -> Solid:
    """The solid union of shapes, each with its pose X (4×4) in the common frame: overlaps
    count once. When the shapes do not overlap, the props are the sum of the parts' (exact
    for primitives); otherwise they are the union mesh's."""
    moved = [p.manifold.transform(X[:3, :4]) for p, X in parts]
    whole = Manifold.batch_boolean(moved, OpType.Add) if len(moved) > 1 else moved[0]
    notes = [n for p, _ in parts for n in p.notes]
    closed_ = all(p.closed for p, _ in parts)
    separate = sum(m.volume() for m in moved)
    if abs(whole.volume() - separate) <= RELATIVE * max(separate, 1e-300):
        props = combine(*(placed(p.props, X) for p, X in parts))
    else:
        props = of_trimesh(to_trimesh(whole))
    return Solid(props, whole, closed_, notes)
