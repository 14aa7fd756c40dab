"""The plain mesh path (core/mesh_arrays.py) against trimesh on every example-robot-data mesh.

Each STL and DAE file is read by both: the triangles (vertices of each face) must be equal,
and so must the bytes written: STL as read and mirrored, OBJ of an STL. A file the plain path
declines (textures, broken references) is left to trimesh, which must then read it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mpc.core import mesh_arrays
from tests.conftest import ERD

MESHES = sorted(p for p in ERD.rglob("*") if p.is_file() and p.suffix.lower() in (".stl", ".dae"))


def _trimesh(path: Path):  # a trimesh.Trimesh
    from mpc.ir.mesh_source import _parse

    return _parse(path, path.suffix.lower(), [])


def test_the_corpus_is_there() -> None:
    assert len(MESHES) > 600


@pytest.mark.parametrize("path", MESHES, ids=lambda p: str(p.relative_to(ERD)))
def test_plain_path_equals_trimesh(path: Path) -> None:
    data = path.read_bytes()
    plain = mesh_arrays.decode(data, path.suffix)
    mesh = _trimesh(path)
    if plain is None:  # declined: trimesh reads it
        assert path.suffix.lower() == ".dae" and len(mesh.faces) > 0
        return
    reflect = np.eye(4)
    reflect[1, 1] = -1.0
    mirrored = mesh.copy()
    mirrored.apply_transform(reflect)
    plain_mirrored = mesh_arrays.transform(plain, reflect)
    ours = plain.vertices[plain.faces]
    theirs = np.asarray(mesh.vertices)[np.asarray(mesh.faces)]
    assert ours.shape == theirs.shape
    assert np.array_equal(ours, theirs)
    assert np.array_equal(plain_mirrored.vertices[plain_mirrored.faces],
                          np.asarray(mirrored.vertices)[np.asarray(mirrored.faces)])
    assert mesh_arrays.encode_stl(plain) == mesh.export(file_type="stl")
    assert mesh_arrays.encode_stl(plain_mirrored) == mirrored.export(file_type="stl")
    if path.suffix.lower() == ".stl":
        name = mesh_arrays.obj_name(data, path.name)
        assert name is not None
        assert mesh_arrays.encode_obj(plain, name) == mesh.export(file_type="obj").encode()
        assert mesh_arrays.encode_obj(plain_mirrored, name) == mirrored.export(file_type="obj").encode()


def test_a_file_the_plain_path_does_not_reproduce_is_declined(tmp_path: Path) -> None:
    """Not finite, out of range, several solids, a texture: None (trimesh says why)."""
    solid = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex {x} 1 0\n" \
            "endloop\nendfacet\nendsolid a\n"
    assert mesh_arrays.decode(solid.format(x="0").encode(), ".stl") is not None
    assert mesh_arrays.decode(solid.format(x="nan").encode(), ".stl") is None
    assert mesh_arrays.decode((solid.format(x="0") * 2).encode(), ".stl") is None
    assert mesh_arrays.decode(b"<COLLADA><texture/></COLLADA>", ".dae") is None
    assert mesh_arrays.decode(b"not xml", ".dae") is None
