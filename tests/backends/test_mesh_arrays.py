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


IDENTITY = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1"


def _dae(material: str = "#m", p: str = "0 1 2", unit: str = "1", matrix: str = IDENTITY) -> bytes:
    """A COLLADA file of one triangle (a polylist of vcount 3) under a node with `matrix`."""
    return f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter="{unit}"/></asset>
 <library_effects><effect id="e"><profile_COMMON><technique sid="t"><phong/></technique>
 </profile_COMMON></effect></library_effects>
 <library_materials><material id="m"><instance_effect url="#e"/></material></library_materials>
 <library_geometries><geometry id="g"><mesh>
  <source id="g-pos"><float_array id="g-pos-a" count="9">0 0 0 1 0 0 0 1 0</float_array>
   <technique_common><accessor source="#g-pos-a" count="3" stride="3">
    <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
   </accessor></technique_common></source>
  <vertices id="g-v"><input semantic="POSITION" source="#g-pos"/></vertices>
  <polylist material="s" count="1"><input semantic="VERTEX" source="#g-v" offset="0"/>
   <vcount>3</vcount><p>{p}</p></polylist>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><matrix>{matrix}</matrix>
  <instance_geometry url="#g"><bind_material><technique_common>
   <instance_material symbol="s" target="{material}"/></technique_common></bind_material></instance_geometry>
 </node></visual_scene></library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>""".encode()


def test_a_dae_is_read_with_its_node_and_unit_or_declined(tmp_path: Path) -> None:
    """Its triangle moved by its node and scaled by its unit, as trimesh reads it; a broken
    material reference (W0605, reported through trimesh), an index out of range or a word that
    is no number: declined."""
    moved = _dae(unit="0.5", matrix="1 0 0 2 0 1 0 0 0 0 1 0 0 0 0 1")
    plain = mesh_arrays.decode(moved, ".dae")
    assert plain is not None
    path = tmp_path / "moved.dae"
    path.write_bytes(moved)
    mesh = _trimesh(path)
    assert np.array_equal(plain.vertices[plain.faces], np.asarray(mesh.vertices)[np.asarray(mesh.faces)])
    assert plain.vertices[plain.faces].tolist() == [[[1.0, 0.0, 0.0], [1.5, 0.0, 0.0], [1.0, 0.5, 0.0]]]
    assert mesh_arrays.decode(_dae(material="#missing"), ".dae") is None
    assert mesh_arrays.decode(_dae(p="0 1 3"), ".dae") is None
    assert mesh_arrays.decode(_dae(p="0 1 x"), ".dae") is None


@pytest.mark.parametrize("rel", ["ur_description/meshes/ur5/visual/forearm.dae",
                                 "talos_data/meshes/arm/arm_1_collision.STL"])
def test_scales_and_reflections_in_turn_equal_trimesh(rel: str) -> None:
    """mesh ops one after another (backends/plain_meshes.py): a scale by three factors, one of
    them negative (a reflection), then a reflection across x, as trimesh applies them."""
    from mpc.backends.plain_meshes import derive
    from mpc.ir.geometry import ReflectMesh, ScaleMesh

    path = ERD / rel
    ops = (ScaleMesh(scale=(0.5, -2.0, 1.5)), ReflectMesh(axis=0))
    mesh = _trimesh(path)
    mesh.apply_scale(np.asarray(ops[0].scale))
    reflect = np.eye(4)
    reflect[0, 0] = -1.0
    mesh.apply_transform(reflect)
    stl = path.suffix.lower() == ".stl"
    made = derive(path, [(ops, Path("x.stl")), *([(ops, Path("x.obj"))] if stl else [])])
    assert made is not None
    assert made[Path("x.stl")] == mesh.export(file_type="stl")
    if stl:
        assert made[Path("x.obj")] == mesh.export(file_type="obj").encode()
