"""Solids (ir/solids.py, manifold3d): unions count overlaps once, concave meshes keep their
true volume, inertia from geometry matches the formulas, meshes that are not closed are
repaired or stood in for by their hull with a warning; on real meshes of example-robot-data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from lxml import etree

from mpc.backends.urdf_reader import read
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.geometry import Box, Mesh, MeshSource, ReflectMesh
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.mesh_props import as_trimesh, solid
from mpc.ir.solids import closed, to_trimesh, union
from tests.conftest import ERD, Diags, compile_file, definition, write

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"


def _at(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    X = np.eye(4)
    X[:3, 3] = (x, y, z)
    return X


def _box_inertia(mass: float, a: float, b: float, c: float) -> np.ndarray:
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _mesh(path: Path, mesh: trimesh.Trimesh) -> Mesh:
    mesh.export(path)
    return Mesh(source=MeshSource(uri=path.name, path=path))


def test_two_overlapping_boxes_count_their_overlap_once() -> None:
    """A unit cube at the origin and a 2×1×1 box from x = 0 to 2: the union is a 2.5×1×1 box
    from x = −0.5 (volume 2.5, centre x = 0.75); the sum of the parts would give 3 and 0.667."""
    whole = union([(solid(Box(size=(1.0, 1.0, 1.0))), np.eye(4)),
                   (solid(Box(size=(2.0, 1.0, 1.0))), _at(1.0))])
    assert whole.closed and not whole.notes
    assert whole.props.mass == pytest.approx(2.5, abs=1e-12)
    np.testing.assert_allclose(whole.props.com, [0.75, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(whole.props.I, _box_inertia(2.5, 2.5, 1.0, 1.0), atol=1e-12)
    parts_sum = 1.0 + 2.0
    assert abs(whole.props.mass - parts_sum) > 0.4 and abs((0 * 1 + 1 * 2) / 3 - 0.75) > 0.08


def test_disjoint_primitives_are_summed_exactly() -> None:
    """Two boxes 2 m apart do not overlap: the parallel-axis sum of the exact parts."""
    whole = union([(solid(Box(size=(1.0, 1.0, 1.0))), np.eye(4)),
                   (solid(Box(size=(1.0, 1.0, 1.0))), _at(2.0))])
    assert whole.props.mass == 2.0
    expected = 2 * _box_inertia(1.0, 1.0, 1.0, 1.0) + np.diag([0.0, 2.0, 2.0])  # 2 · 1 · 1² off-axis
    np.testing.assert_allclose(whole.props.I, expected, atol=1e-15)


def _l_shape() -> trimesh.Trimesh:
    """An L of unit cubes: three along x from (0, 0, 0) and one on top of the first (volume 4,
    hull volume 5), as one closed mesh."""
    cubes = [(solid(Box(size=(3.0, 1.0, 1.0))), _at(1.5, 0.5, 0.5)), (solid(Box(size=(1.0, 1.0, 1.0))),
                                                                     _at(0.5, 0.5, 1.5))]
    return to_trimesh(union(cubes).manifold)


def test_a_concave_mesh_keeps_its_true_volume_not_its_hulls(tmp_path: Path) -> None:
    mesh = _l_shape()
    assert mesh.convex_hull.volume == pytest.approx(5.0)
    shape = solid(_mesh(tmp_path / "l.stl", mesh))
    assert shape.closed and not shape.notes
    assert shape.props.mass == pytest.approx(4.0, abs=1e-12)
    # centre: (3·(1.5, .5, .5) + (.5, .5, 1.5)) / 4
    np.testing.assert_allclose(shape.props.com, [1.25, 0.5, 0.75], atol=1e-12)


def test_estimate_missing_coms_uses_the_union_and_the_true_volume(tmp_path: Path) -> None:
    """The COM of a link with the L mesh and an overlapping box: the union's centre."""
    _l_shape().export(tmp_path / "l.stl")
    urdf = write(tmp_path / "l.urdf", """
        <robot name="ell">
          <link name="base">
            <inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
            <collision><geometry><mesh filename="l.stl"/></geometry></collision>
            <collision><origin xyz="1.5 0.5 0.5"/><geometry><box size="3 1 1"/></geometry></collision>
          </link>
        </robot>
        """)
    out = _compile(tmp_path, urdf, "  frames:\n    base: {estimate_missing_coms: true}\n")
    origin = etree.parse(str(out)).getroot().find("link/inertial/origin")
    # the box lies inside the L: the union is the L, and its centre the L's
    np.testing.assert_allclose([float(x) for x in origin.get("xyz").split()], [1.25, 0.5, 0.75], atol=1e-12)


def _compile(tmp_path: Path, urdf: Path, sections: str, name: str = "robot", sink: Diags | None = None,
             exports: str = "") -> Path:
    """Compile `urdf` with the definition's further `sections` (indented by 2)."""
    spec = tmp_path / "m.yml"
    spec.write_text(definition(urdf, mesh_format="stl", robotname=name) + exports + sections)
    sink = sink if sink is not None else Diags()
    result = compile_file(spec, tmp_path / "out", sink)
    assert result.out is not None, sink.summary()
    return result.out / "urdf" / f"{name}.urdf"


@pytest.mark.parametrize("geometry", ["box", "mesh"])
def test_a_box_inertia_from_geometry_is_the_formula(tmp_path: Path, geometry: str) -> None:
    """estimate_missing_inertia on a 0.2×0.1×0.4 box of 3 kg (a primitive, or a mesh turned by
    the collision's rpy): Pinocchio reads m/12·(b² + c², …) in the link frame."""
    trimesh.creation.box(extents=(0.2, 0.1, 0.4)).export(tmp_path / "box.stl")
    shape = '<box size="0.2 0.1 0.4"/>' if geometry == "box" else '<mesh filename="box.stl"/>'
    urdf = write(tmp_path / "b.urdf", f"""
        <robot name="boxy">
          <link name="base"/>
          <joint name="j" type="revolute"><parent link="base"/><child link="body"/><axis xyz="0 0 1"/>
            <limit effort="1" velocity="1" lower="-1" upper="1"/></joint>
          <link name="body">
            <inertial><origin xyz="0 0 0.1"/><mass value="3"/>
              <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
            <collision><origin xyz="0 0 0.1" rpy="0 0 1.5707963267948966"/>
              <geometry>{shape}</geometry></collision>
          </link>
        </robot>
        """)
    out = _compile(tmp_path, urdf, "  frames:\n    body: {estimate_missing_inertia: true}\n", name="boxy")
    model = pin.buildModelFromUrdf(str(out))
    inertia = model.inertias[model.getJointId("j")]
    assert inertia.mass == 3.0
    np.testing.assert_allclose(inertia.lever, [0, 0, 0.1], atol=1e-15)
    # turned by 90° about z: x and y swap their extents
    np.testing.assert_allclose(inertia.inertia, _box_inertia(3.0, 0.1, 0.2, 0.4), atol=1e-12)


def test_an_open_mesh_is_repaired_or_replaced_by_its_hull_with_a_warning(tmp_path: Path) -> None:
    """A box with one side missing (a hole of four edges) is closed again; a cylinder without
    its caps (holes of 32 edges) is not repaired: its hull stands in, and W0580 names it."""
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    side = np.flatnonzero(box.face_normals[:, 0] > 0.5)
    open_box = trimesh.Trimesh(box.vertices, np.delete(box.faces, side, axis=0))
    repaired = solid(_mesh(tmp_path / "open_box.stl", open_box))
    assert repaired.closed and repaired.props.mass == pytest.approx(1.0, abs=1e-12)
    assert repaired.notes == [("W0581", "mesh 'open_box.stl' was not a closed solid; repaired "
                                        "(closed 4 open edges)")]
    tube = trimesh.creation.cylinder(radius=0.5, height=1.0, sections=32)
    walls = tube.faces[np.abs(tube.face_normals[:, 2]) < 0.5]
    hull = solid(_mesh(tmp_path / "tube.stl", trimesh.Trimesh(tube.vertices, walls)))
    assert not hull.closed
    assert hull.props.mass == pytest.approx(tube.volume, rel=1e-6)  # the hull: the cylinder (STL: float32)
    assert hull.notes == [("W0580", "mesh 'tube.stl' is not a closed solid (64 open edges after merging "
                                    "vertices and closing small holes); its convex hull stands in for it")]


def test_the_hull_warning_reaches_the_user(tmp_path: Path) -> None:
    tube = trimesh.creation.cylinder(radius=0.5, height=1.0, sections=32)
    walls = tube.faces[np.abs(tube.face_normals[:, 2]) < 0.5]
    trimesh.Trimesh(tube.vertices, walls).export(tmp_path / "tube.stl")
    urdf = write(tmp_path / "t.urdf", """
        <robot name="tube">
          <link name="base">
            <inertial><mass value="2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
            <collision><geometry><mesh filename="tube.stl"/></geometry></collision>
          </link>
        </robot>
        """)
    sink = Diags()
    _compile(tmp_path, urdf, "  frames:\n    base: {estimate_missing_inertia: true}\n", "tube", sink)
    warning = sink.take("W0580", Severity.WARNING)
    assert warning.message == ("estimate_missing_inertia of link 'base': mesh 'tube.stl' is not a closed "
                               "solid (64 open edges after merging vertices and closing small holes); its "
                               "convex hull stands in for it")
    assert (warning.span.line, warning.span.col) == (13, 5)  # the link's entry


def test_the_union_of_talos_leg_collisions_is_closed() -> None:
    """Every collision mesh of TALOS's left leg, placed at q = 0, unioned: one closed solid,
    smaller than the sum of the parts (the links' meshes overlap at the joints)."""
    robot = read(TALOS, Sink())
    assert robot is not None
    parts = [(solid(c.geometry), link_in_root(robot, name) @ pose_matrix(c.origin))
             for name, link in robot.links.items() if name.startswith("leg_left_") for c in link.collisions]
    assert len(parts) == 6 and all(p.closed and not p.notes for p, _ in parts)
    whole = union(parts)
    assert whole.closed and whole.manifold.status().name == "NoError"
    mesh = to_trimesh(whole.manifold)
    assert closed(mesh) and mesh.is_watertight and mesh.is_winding_consistent
    separate = sum(p.props.mass for p, _ in parts)
    assert 0.5 * separate < whole.props.mass < 0.95 * separate
    assert mesh.volume == pytest.approx(whole.props.mass, rel=1e-9)


def test_the_mirror_of_a_closed_talos_mesh_is_closed_with_equal_volume() -> None:
    path = ERD / "talos_data/meshes/v2/knee_collision.stl"
    assert path.is_file()
    source = MeshSource(uri=path.name, path=path)
    original = solid(Mesh(source=source))
    for axis in range(3):
        mirrored = as_trimesh(Mesh(source=source, ops=(ReflectMesh(axis),)))
        assert closed(mirrored)
        shape = solid(Mesh(source=source, ops=(ReflectMesh(axis),)))
        assert shape.closed and not shape.notes
        assert shape.props.mass == pytest.approx(original.props.mass, rel=1e-12)
        expected = original.props.com.copy()
        expected[axis] *= -1
        np.testing.assert_allclose(shape.props.com, expected, atol=1e-12)


def test_a_mesh_with_nan_vertices_is_an_error_and_an_empty_one_a_warning(tmp_path: Path) -> None:
    write(tmp_path / "nan.stl", """
        solid t
        facet normal 0 0 1
        outer loop
        vertex nan 0 0
        vertex 1 0 0
        vertex 0 1 0
        endloop
        endfacet
        endsolid t
        """)
    write(tmp_path / "empty.stl", "solid empty\nendsolid empty\n")
    urdf = write(tmp_path / "n.urdf", """
        <robot name="bad">
          <link name="base">
            <inertial><mass value="2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
            <collision><geometry><mesh filename="nan.stl"/></geometry></collision>
          </link>
          <joint name="j" type="fixed"><parent link="base"/><child link="tip"/></joint>
          <link name="tip">
            <inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
            <collision><geometry><mesh filename="empty.stl"/></geometry></collision>
          </link>
        </robot>
        """)
    spec = tmp_path / "m.yml"
    spec.write_text(definition(urdf, mesh_format="stl", robotname="bad")
                    + "  frames:\n    $default: {estimate_missing_inertia: true}\n")
    sink = Diags()
    assert compile_file(spec, tmp_path / "out", sink).out is None
    assert sink.take_error("E0602").message == (
        f"estimate_missing_inertia of link 'base': cannot read mesh '{tmp_path / 'nan.stl'}': a vertex "
        "has a coordinate that is not a finite number (nan or inf)")
    assert sink.take("W0580", Severity.WARNING).message == ("estimate_missing_inertia of link 'tip': mesh "
                                                            "'empty.stl' has no triangles: it adds no volume")
