"""The triangles of a robot's meshes, for a USD export: each distinct mesh value (file and ops)
computed once through the mesh cache (backends/meshes.py) as binary PLY, then read here.

USD holds a mesh's points and faces in the layer itself, so the USD export writes no mesh
files: the PLY files go to a temporary folder, each read back into NumPy arrays (points
float32, face indices int32) by `read_ply`, a reader of the binary PLY that trimesh writes
(anything else is read by trimesh).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from mpc.backends import meshes
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.robot import Robot

Triangles = tuple[np.ndarray, np.ndarray]  # points (n, 3) float32, triangles (m, 3) int32

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
    points = np.stack([vertices[c].astype(np.float32) for c in ("x", "y", "z")], axis=1)
    return points, faces["i"].astype(np.int32)


def _read(path: Path) -> Triangles:
    parsed = read_ply(path.read_bytes())
    if parsed is not None:
        return parsed
    import trimesh

    mesh: Any = trimesh.load(path, force="mesh", process=False)
    return np.asarray(mesh.vertices, dtype=np.float32), np.asarray(mesh.faces, dtype=np.int32)


def triangles(robot: Robot, sink: Sink, span: Span) -> dict[meshes.MeshKey, Triangles] | None:
    """The triangles of every mesh of `robot` by its key (backends/meshes.py `key`), unscaled
    (the element's scale is the USD prim's); None after an error (reported)."""
    files = meshes.plan(robot, "ply", sink, span)
    if files is None:
        return None
    if not files:
        return {}
    with tempfile.TemporaryDirectory(prefix="mpc-usd-") as work:
        folder = Path(work)
        if not meshes.copy(files, folder, sink, span, robot):
            return None
        return {k: _read(folder / rel) for k, rel in files.items()}
