"""Geometry values of visuals and collisions: box, cylinder, sphere, mesh.

A mesh is a *value*: the file it comes from plus the chain of mesh operations
recorded on it (mirror, scale, reduce, …). Reading a model never opens a mesh file;
backends materialise each distinct chain once, at emission.
"""

from __future__ import annotations

from pathlib import Path

from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.core.span import Span

Vec3 = tuple[float, float, float]
Attrs = tuple[tuple[str, str], ...]


@record(slots=True, kw_only=True, bulk=True)
class Box:
    """A box centred at its origin. size: edge lengths along x, y, z in metres."""

    size: Vec3
    extra_attrs: Attrs = ()


@record(slots=True, kw_only=True, bulk=True)
class Cylinder:
    """A cylinder along z, centred at its origin. radius and length in metres."""

    radius: float
    length: float
    extra_attrs: Attrs = ()


@record(slots=True, kw_only=True, bulk=True)
class Sphere:
    """A sphere centred at its origin. radius in metres."""

    radius: float
    extra_attrs: Attrs = ()


@record(slots=True, kw_only=True, bulk=True)
class MeshSource:
    """Where a mesh file comes from.

    uri: the filename as written in the source model (`package://…`, relative, `file://…`).
    path: the file it resolves to, or None when its package could not be found.
    unresolved: why `path` is None (a sentence for a diagnostic), else "".
    """

    uri: str
    path: Path | None
    unresolved: str = ""

    @property
    def format(self) -> str:
        """The file format by extension, lower case without the dot ("stl", "dae", …)."""
        name = self.path.name if self.path is not None else self.uri
        return name.rsplit(".", 1)[-1].lower() if "." in name else ""


GENERATED = "mpc-generated:"  # the uri of a mesh mpc makes from shapes; no file holds it


def generated_source(name: str) -> MeshSource:
    """The source of a mesh mpc makes from shapes (a `join` of primitives), named `name`.stl."""
    return MeshSource(uri=f"{GENERATED}{name}.stl", path=None)


def is_generated(source: MeshSource) -> bool:
    """Whether the mesh is made by mpc from shapes, not read from a file."""
    return source.path is None and source.uri.startswith(GENERATED)


def mesh_source(resolver: PackageResolver, uri: str, base_dir: Path) -> MeshSource:
    """The MeshSource of a filename written in a model file in `base_dir`."""
    path, unresolved = resolver.locate(uri, base_dir)
    return MeshSource(uri=uri, path=path, unresolved=unresolved)


@record(slots=True)
class ReflectMesh:
    """Mesh op: reflect the mesh's vertices along one of its axes (0 x, 1 y, 2 z).

    Materialised with the triangle winding reversed, so normals point outwards and the
    volume stays positive.
    """

    axis: int


@record(slots=True)
class ConvexHull:
    """Mesh op: replace the mesh by its convex hull."""


@record(slots=True)
class JoinShapes:
    """Mesh op: the mesh becomes the union of `parts`, each a shape with its pose (xyz, rpy)
    in this mesh's frame. The source file then only names the result.

    solid: the solid (boolean) union, one closed mesh (ir/solids.py); otherwise the parts'
    triangles side by side (what a convex hull of them needs).
    """

    parts: tuple[tuple[Geometry, Vec3, Vec3], ...]
    solid: bool = False


@record(slots=True)
class ReduceMesh:
    """Mesh op: quadric decimation to `faces` faces, or to `ratio` of them (one is given)."""

    faces: int | None = None
    ratio: float | None = None


@record(slots=True)
class ScaleMesh:
    """Mesh op: scale the vertices (`apply_scale` bakes an element's scale into its file)."""

    scale: Vec3


@record(slots=True)
class ConvexPart:
    """Mesh op: part `index` of the convex decomposition (coacd) of the mesh so far, scaled
    by `scale` (the element's scale moves here: the element that uses the part has none)."""

    index: int
    scale: Vec3 | None = None


@record(slots=True)
class MaterialPart:
    """Mesh op, first when present: the triangles of the file's `index`-th material colour (a
    DAE file's, in the order the colours first appear: core/collada.py `material_parts`).
    Only pictures use it (backends/scene.py), to draw each material in its colour."""

    index: int


MeshOp = ReflectMesh | ConvexHull | JoinShapes | ReduceMesh | ScaleMesh | ConvexPart | MaterialPart


@record(slots=True, kw_only=True, bulk=True)
class Mesh:
    """A triangle mesh.

    source: the file and how it was found.
    scale: the scale written on the element, or None when none was written.
    ops: mesh operations recorded on this value, applied in order at emission.
    span: the `<mesh>` element (or YAML) the mesh was read from, for diagnostics.
    """

    source: MeshSource
    scale: Vec3 | None = None
    ops: tuple[MeshOp, ...] = ()
    span: Span | None = None
    extra_attrs: Attrs = ()


Geometry = Box | Cylinder | Sphere | Mesh


class MeshError(Exception):
    """A mesh file cannot be read (the caller turns it into a diagnostic). Here, not beside the
    readers (ir/mesh_props.py), so that catching it imports no trimesh."""
