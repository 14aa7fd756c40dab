"""The triangles of a robot's meshes, for a USD export: each distinct mesh value (file and ops)
computed once through the mesh cache (backends/meshes.py) as binary PLY, then read here.

USD holds a mesh's points and faces in the layer itself, so the USD export writes no mesh
files: each PLY's bytes, as the cache holds them, are read into NumPy arrays (points float32,
face indices int32) by `read_ply`, a reader of the binary PLY that trimesh writes (anything
else is read by trimesh).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from mpc.backends import meshes
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.robot import Robot


class Triangles(NamedTuple):
    points: np.ndarray  # (n, 3) float32
    faces: np.ndarray  # (m, 3) int32
    extent: tuple[tuple[float, ...], tuple[float, ...]]  # the points' least and greatest x, y, z


_SCALARS = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "<i2", "ushort": "<u2",
            "int16": "<i2", "uint16": "<u2", "int": "<i4", "uint": "<u4", "int32": "<i4",
            "uint32": "<u4", "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8"}


def read_ply(data: bytes) -> Triangles | None:
    """Points and triangles of a binary little-endian PLY whose faces are all triangles (what
    trimesh writes), or None for another kind of PLY."""
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        return None
    header = data[:end].decode("ascii", "replace").splitlines()
    if "format binary_little_endian 1.0" not in header:
        return None
    elements: list[tuple[str, int, list[list[str]]]] = []
    for line in header:
        words = line.split()
        if words[:1] == ["element"] and len(words) == 3:
            elements.append((words[1], int(words[2]), []))
        elif words[:1] == ["property"] and elements:
            elements[-1][2].append(words[1:])
    if [e[0] for e in elements] != ["vertex", "face"]:
        return None
    (_, nv, vprops), (_, nf, fprops) = elements
    scalar = [p for p in (*vprops, *fprops[1:]) if len(p) == 2 and p[0] in _SCALARS]
    if len(scalar) != len(vprops) + len(fprops) - 1 or not fprops or len(fprops[0]) != 4 \
            or fprops[0][0] != "list" or fprops[0][1] not in _SCALARS or fprops[0][2] not in _SCALARS:
        return None
    vtype = np.dtype([(p[1], _SCALARS[p[0]]) for p in vprops])
    # the face's list first (three indices, trimesh's triangles), then its other properties
    ftype = np.dtype([("n", _SCALARS[fprops[0][1]]), ("i", _SCALARS[fprops[0][2]], (3,)),
                      *((f"_{k}", _SCALARS[p[0]]) for k, p in enumerate(fprops[1:]))])
    start = end + len(b"end_header\n")
    if len(data) < start + nv * vtype.itemsize + nf * ftype.itemsize:
        return None
    vertices = np.frombuffer(data, vtype, nv, start)
    faces = np.frombuffer(data, ftype, nf, start + nv * vtype.itemsize)
    if not np.all(faces["n"] == 3):
        return None
    columns = [vertices[c].astype(np.float32) for c in ("x", "y", "z")]
    # the extent from the columns: a minimum down a contiguous column is ten times one down (n, 3)
    extent = ((tuple(float(c.min()) for c in columns), tuple(float(c.max()) for c in columns))
              if nv else ((), ()))
    return Triangles(np.stack(columns, axis=1), faces["i"].astype(np.int32), extent)


def _read(content: bytes | Path) -> Triangles:
    """The triangles of a mesh's bytes from the cache (or of a PLY source file used as it is)."""
    parsed = read_ply(content if isinstance(content, bytes) else content.read_bytes())
    if parsed is not None:
        return parsed
    import trimesh

    source = io.BytesIO(content) if isinstance(content, bytes) else content
    mesh: Any = trimesh.load(source, file_type="ply", force="mesh", process=False)
    points = np.asarray(mesh.vertices, dtype=np.float32)
    extent = ((tuple(map(float, points.min(axis=0))), tuple(map(float, points.max(axis=0))))
              if len(points) else ((), ()))
    return Triangles(points, np.asarray(mesh.faces, dtype=np.int32), extent)


def not_finite(sink: Sink, span: Span, where: str) -> None:
    """E0589: the USD would hold a number that is not finite (at `where`); none is written."""
    sink.error(span, "E0589", "the USD would hold a number that is not finite, beyond ±3.4e38 (the "
               f"32-bit floats of UsdGeom and UsdPhysics): {where}; no USD is written",
               hint="a length, mass or angle of the model is out of any physical range")


def triangles(robot: Robot, sink: Sink, span: Span) -> dict[meshes.MeshKey, Triangles] | None:
    """The triangles of every mesh of `robot` by its key (backends/meshes.py `key`), unscaled
    (the element's scale is the USD prim's); None after an error (reported)."""
    files = meshes.plan(robot, "ply", sink, span)
    if files is None:
        return None
    found, ok = meshes.contents(files, sink, span, robot)
    if not ok:
        return None
    read = {k: _read(found[rel]) for k, rel in files.items()}
    for (source, _), mesh in read.items():
        if not np.isfinite(mesh.points).all():  # a coordinate beyond ±3.4e38 became infinite
            not_finite(sink, span, f"a point of mesh '{source}'")
            return None
    return read
