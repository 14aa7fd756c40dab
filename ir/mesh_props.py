"""Shapes as triangle meshes (trimesh) and as solids, for the ops that need geometry: bounding
primitives, and the meshes ir/solids.py makes solids of. Imported only by those ops.

The one recursive evaluation of a shape's mesh ops: a convex part needs the shape before it
(ir/decompose.py) and a solid join needs its parts' solids (ir/solids.py); both of those
modules work on meshes given to them and import nothing of this one."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import trimesh

from mpc.ir import transforms as tf
from mpc.ir.geometry import (
    Box,
    ConvexHull,
    ConvexPart,
    Cylinder,
    Geometry,
    JoinShapes,
    MaterialPart,
    Mesh,
    MeshError,
    ReduceMesh,
    ReflectMesh,
    ScaleMesh,
    Sphere,
)

if TYPE_CHECKING:
    from mpc.ir.solids import Solid


def as_trimesh(geometry: Geometry, scaled: bool = True, ignored: list[str] | None = None) -> trimesh.Trimesh:
    """The shape in its own frame with its mesh ops applied; scaled unless told not to
    (a URDF keeps the scale on the element, so files are written unscaled).

    ignored: receives the broken references of a DAE file that were ignored to read it.
    """
    if isinstance(geometry, Box):
        return trimesh.creation.box(extents=geometry.size)
    if isinstance(geometry, Cylinder):
        return trimesh.creation.cylinder(radius=geometry.radius, height=geometry.length, sections=64)
    if isinstance(geometry, Sphere):
        return trimesh.creation.icosphere(subdivisions=3, radius=geometry.radius)
    assert isinstance(geometry, Mesh)
    if geometry.ops and isinstance(geometry.ops[0], JoinShapes):
        mesh = None  # the parts make the mesh; the file only names it
    elif geometry.ops and isinstance(geometry.ops[0], MaterialPart):
        from mpc.core.collada import material_parts

        try:
            mesh = material_parts(geometry.source.path)[geometry.ops[0].index][1].copy()  # type: ignore[arg-type]
        except Exception as e:  # as for a whole file: cannot read this one
            raise MeshError(f"cannot read mesh '{geometry.source.path}': {e}") from None
    else:
        path = geometry.source.path
        if path is None or not path.is_file():
            raise MeshError(f"mesh '{geometry.source.uri}' cannot be found")
        try:
            from mpc.ir import mesh_source

            mesh = mesh_source.read(path, ignored)  # parsed once per content, ever
        except Exception as e:  # trimesh raises many kinds; all mean "cannot read this file"
            raise MeshError(f"cannot read mesh '{path}': {e}") from None
    for n, op in enumerate(geometry.ops):
        if isinstance(op, ConvexPart):
            from mpc.ir.decompose import parts

            before = Mesh(source=geometry.source, scale=op.scale, ops=geometry.ops[:n])
            mesh = parts(before, as_trimesh)[op.index]
            continue
        if isinstance(op, ReflectMesh):
            T = np.eye(4)
            T[op.axis, op.axis] = -1.0
            mesh.apply_transform(T)  # trimesh reverses the winding for a reflection
        elif isinstance(op, ConvexHull):
            mesh = mesh.convex_hull
        elif isinstance(op, ReduceMesh):
            target = op.faces if op.faces is not None else int(len(mesh.faces) * (op.ratio or 1.0))
            if 4 <= target < len(mesh.faces):
                # An STL file is a triangle soup: decimated unmerged, its triangles come apart
                # and a closed mesh comes out open (W0582).
                mesh.merge_vertices()
                mesh = mesh.simplify_quadric_decimation(face_count=target)
        elif isinstance(op, ScaleMesh):
            mesh.apply_scale(np.asarray(op.scale))
        elif isinstance(op, MaterialPart):
            continue  # read above
        elif isinstance(op, JoinShapes) and op.solid:
            from mpc.ir.solids import to_trimesh, union

            mesh = to_trimesh(union([(solid(shape), tf.pose_to_matrix(xyz, rpy))
                                     for shape, xyz, rpy in op.parts]).manifold)
        elif isinstance(op, JoinShapes):
            pieces = [] if mesh is None else [mesh]
            for shape, xyz, rpy in op.parts:
                piece = as_trimesh(shape, ignored=ignored)
                piece.apply_transform(tf.pose_to_matrix(xyz, rpy))
                pieces.append(piece)
            mesh = trimesh.util.concatenate(pieces)
    if scaled and geometry.scale is not None:
        mesh.apply_scale(np.asarray(geometry.scale))
    return mesh


def bounding(geometry: Geometry, shape: str, oriented: bool) -> tuple[Geometry, np.ndarray]:
    """The bounding box, cylinder or sphere of a shape, and its pose X_GB in the shape's frame.

    oriented: the smallest box (or cylinder) in any orientation; otherwise aligned with the
    shape's own axes.
    """
    mesh = as_trimesh(geometry)
    if shape == "sphere":
        centre, radius = trimesh.nsphere.minimum_nsphere(mesh.vertices)
        X = np.eye(4)
        X[:3, 3] = centre
        return Sphere(radius=float(radius)), X
    if shape == "box":
        if oriented:
            X, extents = trimesh.bounds.oriented_bounds(mesh)
            return Box(size=tuple(float(e) for e in extents)), np.linalg.inv(X)  # type: ignore[arg-type]
        lo, hi = mesh.bounds
        X = np.eye(4)
        X[:3, 3] = (lo + hi) / 2
        return Box(size=tuple(float(e) for e in hi - lo)), X  # type: ignore[arg-type]
    if oriented:
        fit = trimesh.bounds.minimum_cylinder(mesh)
        return Cylinder(radius=float(fit["radius"]), length=float(fit["height"])), fit["transform"]
    lo, hi = mesh.bounds  # along the shape's z axis
    centre = (lo + hi) / 2
    radius = float(np.max(np.linalg.norm(mesh.vertices[:, :2] - centre[:2], axis=1)))
    X = np.eye(4)
    X[:3, 3] = centre
    return Cylinder(radius=radius, length=float(hi[2] - lo[2])), X


def scaled(shape: Geometry, factor: float) -> Geometry:
    """A primitive with its dimensions multiplied by `factor`."""
    if factor == 1.0:
        return shape
    if isinstance(shape, Box):
        return Box(size=tuple(factor * x for x in shape.size))  # type: ignore[arg-type]
    if isinstance(shape, Cylinder):
        return Cylinder(radius=factor * shape.radius, length=factor * shape.length)
    assert isinstance(shape, Sphere)
    return Sphere(radius=factor * shape.radius)



def solid(geometry: Geometry) -> Solid:
    """The shape (with its mesh ops and scale) as a solid (ir/solids.py); MeshError when its
    file cannot be read or its vertices are not finite numbers."""
    from mpc.ir.solids import mesh_name, solid_of_mesh, solid_of_primitive

    if isinstance(geometry, Box | Cylinder | Sphere):
        return solid_of_primitive(geometry)
    assert isinstance(geometry, Mesh)
    mesh = as_trimesh(geometry)  # a negative scale reflects; trimesh turns the triangles back out
    try:
        return solid_of_mesh(mesh, mesh_name(geometry))
    except ValueError as e:
        raise MeshError(str(e)) from None
