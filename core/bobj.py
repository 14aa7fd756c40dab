"""MARS's binary OBJ (`bobj`), as Phobos writes and reads it.

A sequence of records, each an int32 key and its values, little-endian: 1 → a vertex
(3 float32), 2 → a texture coordinate (2 float32), 3 → a vertex normal (3 float32),
4 → a triangle (3 corners × 3 int32: vertex, texture and normal index, 1-based as in OBJ,
0 for none). mpc writes vertices, vertex normals and triangles.
"""

from __future__ import annotations

import struct

import numpy as np
import trimesh


def dumps(mesh: trimesh.Trimesh) -> bytes:
    """The bobj bytes of `mesh` (one normal per vertex, corners v//n)."""
    vertices = np.asarray(mesh.vertices, dtype="<f4")
    normals = np.asarray(mesh.vertex_normals, dtype="<f4")
    faces = np.asarray(mesh.faces, dtype="<i4") + 1

    def records(key: int, rows: np.ndarray) -> bytes:
        keys = np.full((len(rows), 1), key, dtype="<i4").view("<f4" if rows.dtype.kind == "f" else "<i4")
        return np.hstack([keys, rows]).astype(rows.dtype).tobytes()

    corners = np.stack([faces, np.zeros_like(faces), faces], axis=2).reshape(len(faces), 9)
    return records(1, vertices) + records(3, normals) + records(4, corners.astype("<i4"))


def loads(data: bytes) -> trimesh.Trimesh:
    """A mesh from bobj bytes (vertices and triangles; normals and texture coordinates
    are read and left to trimesh to recompute)."""
    sizes = {1: (3, "<f4"), 2: (2, "<f4"), 3: (3, "<f4"), 4: (9, "<i4")}
    vertices, faces, offset = [], [], 0
    while offset < len(data):
        (key,) = struct.unpack_from("<i", data, offset)
        if key not in sizes:
            raise ValueError(f"unknown bobj record {key} at byte {offset}")
        count, dtype = sizes[key]
        values = np.frombuffer(data, dtype=dtype, count=count, offset=offset + 4)
        if key == 1:
            vertices.append(values)
        elif key == 4:
            faces.append(values.reshape(3, 3)[:, 0] - 1)
        offset += 4 + 4 * count
    return trimesh.Trimesh(np.array(vertices, dtype=float), np.array(faces, dtype=np.int64), process=False)
