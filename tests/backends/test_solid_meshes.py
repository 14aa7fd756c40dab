"""Meshes that stay solids: `join: union` gives one closed mesh that PyBullet and MuJoCo load;
mirrored and reduced meshes of example-robot-data stay closed, and a mesh op that opens one
is a warning naming the link and the op (W0582)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pybullet
import pytest
import trimesh
from lxml import etree

from mpc.backends.urdf_reader import read
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.mesh_props import solid
from mpc.ir.solids import closed, union
from tests.conftest import ERD, Diags, compile_file, write

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"
LOWER_LEG = ("leg_left_4_link", "leg_left_5_link", "leg_left_6_link")


def _compile(tmp_path: Path, text: str, sink: Sink | None = None) -> Path:
    spec = write(tmp_path / "m.yml", text)
    sink = sink if sink is not None else Diags()
    result = compile_file(spec, tmp_path / "out", sink)
    assert result.out is not None, [d.message for d in sink.diagnostics]
    return result.out


def test_join_union_of_talos_lower_leg_is_one_closed_mesh_that_pybullet_and_mujoco_load(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ankle joints removed, the knee link holds the knee, ankle and foot collisions;
    `join: union` makes them one closed mesh whose volume is their union's (less than their
    sum: they overlap at the joints), and both simulators load the model with it."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    out = _compile(tmp_path, f"""
        model:
          robotname: talos
          modelname: talos-leg
          input_models: {{src: {{basefile: "{TALOS}"}}}}
          assemble: {{model: src}}
          joints:
            leg_left_5_joint: {{remove: true}}
            leg_left_6_joint: {{remove: true}}
          collisions:
            leg_left_4_link: {{join: union}}
          export_config:
            - type: urdf
              mesh_format: stl
            - type: mjcf
              mesh_format: stl
        """, sink := Sink())
    assert [d.code for d in sink.diagnostics] == ["W0500"]  # what MJCF cannot hold, nothing else
    root = etree.parse(str(out / "urdf/talos.urdf")).getroot()
    [collision] = root.findall("link[@name='leg_left_4_link']/collision")
    filename = collision.find("geometry/mesh").get("filename")
    assert filename.endswith("knee_collision_joined.stl")
    joined = trimesh.load(out / "urdf" / filename, force="mesh")
    assert closed(joined)
    robot = read(TALOS, Sink())
    assert robot is not None
    X_knee = np.linalg.inv(link_in_root(robot, "leg_left_4_link"))
    parts = [(solid(c.geometry), X_knee @ link_in_root(robot, name) @ pose_matrix(c.origin))
             for name in LOWER_LEG for c in robot.links[name].collisions]
    expected = union(parts).props.mass
    assert joined.volume == pytest.approx(expected, rel=1e-6)  # the file is float32
    assert expected < 0.95 * sum(p.props.mass for p, _ in parts)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(out / "urdf/talos.urdf"), useFixedBase=True, physicsClientId=client)
        names = {pybullet.getJointInfo(body, i, physicsClientId=client)[12].decode()
                 for i in range(pybullet.getNumJoints(body, physicsClientId=client))}
        assert "leg_left_4_link" in names and "leg_left_5_link" not in names
        knee = next(i for i in range(pybullet.getNumJoints(body, physicsClientId=client))
                    if pybullet.getJointInfo(body, i, physicsClientId=client)[12] == b"leg_left_4_link")
        shapes = pybullet.getCollisionShapeData(body, knee, physicsClientId=client)
        assert len(shapes) == 1 and shapes[0][2] == pybullet.GEOM_MESH
    finally:
        pybullet.disconnect(client)
    model = mujoco.MjModel.from_xml_path(str(out / "mjcf/talos.xml"))
    knee_body = model.body("leg_left_4_link").id
    meshes = [model.mesh(int(model.geom_dataid[g])).name for g in range(model.ngeom)
              if model.geom_bodyid[g] == knee_body and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
              and model.geom_contype[g] + model.geom_conaffinity[g] > 0]
    assert any("joined" in name for name in meshes), meshes


def test_mirrored_talos_meshes_stay_closed_with_their_volume(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """The left arm mirrored: every mesh is reflected, and each collision mesh written stays
    closed with its volume (why solid_checks need not read mirrored meshes again)."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    arm = ERD / "talos_data/robots/talos_left_arm.urdf"
    out = _compile(tmp_path, f"""
        model:
          robotname: arm
          modelname: arm-mirrored
          input_models: {{arm: {{basefile: "{arm}"}}}}
          assemble: {{model: arm, mirror: {{}}}}
          export_config:
            - type: urdf
              mesh_format: stl
        """)
    robot = read(arm, Sink())
    assert robot is not None
    sources = {c.geometry.source.path.stem: c.geometry.source.path
               for link in robot.links.values() for c in link.collisions if hasattr(c.geometry, "source")}
    files = sorted((out / "meshes/stl").glob("*_mirrored.stl"))
    checked = 0
    for path in files:
        source = sources.get(path.stem.removesuffix("_mirrored"))
        if source is None:
            continue  # a visual mesh
        mirrored = trimesh.load(path, force="mesh")
        assert closed(mirrored), path.name
        assert mirrored.volume == pytest.approx(trimesh.load(source, force="mesh").volume, rel=1e-6)
        checked += 1
    assert checked == len(sources) >= 7


def test_a_reduction_that_opens_a_closed_mesh_is_a_warning(tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """UR5's wrists decimated to 4 faces come apart (W0582 names link, element and op); to 20
    faces every mesh stays closed, and nothing is said."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    ur5 = ERD / "ur_description/urdf/ur5_robot.urdf"
    text = f"""
        model:
          robotname: ur5
          modelname: ur5-reduced
          input_models: {{src: {{basefile: "{ur5}"}}}}
          assemble: {{model: src}}
          reduce_meshes: FACES
          export_config:
            - type: urdf
              mesh_format: stl
        """
    sink = Diags()
    _compile(tmp_path / "a", text.replace("FACES", "4"), sink)
    found = []
    while any(d.code == "W0582" for d in sink.diagnostics):
        found.append(sink.take("W0582", Severity.WARNING).message)
    assert "mesh 'package://example-robot-data/robots/ur_description/meshes/ur5/collision/wrist1.stl' of a " \
           "collision of link 'wrist_1_link' is a closed solid but not after reduce_meshes" in found
    assert all(m.endswith("is a closed solid but not after reduce_meshes") for m in found)
    quiet = Diags()
    out = _compile(tmp_path / "b", text.replace("FACES", "20"), quiet)
    for path in (out / "meshes/stl").glob("*collision*"):
        assert closed(trimesh.load(path, force="mesh")), path.name


def test_a_mesh_opened_by_a_reduction_is_one_warning_and_only_as_a_collision(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """UR5's wrist mesh, used by the visual and the collision of four links, comes apart at 4
    faces: one W0582 for the mesh, naming the links whose collisions use it (a visual is no
    solid); used by visuals alone, it is not warned about at all."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    wrist = ERD / "ur_description/meshes/ur5/collision/wrist1.stl"

    def robot(collisions: bool) -> str:
        links, joints = [], []
        for i in range(4):
            shape = f'<geometry><mesh filename="{wrist}"/></geometry>'
            collision = f"<collision>{shape}</collision>" if collisions else ""
            links.append(f'<link name="l{i}"><visual>{shape}</visual>{collision}</link>')
            if i:
                joints.append(f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/>'
                              f'<child link="l{i}"/></joint>')
        return f'<robot name="wrists">{"".join(links)}{"".join(joints)}</robot>\n'

    for name, collisions in (("both", True), ("visual", False)):
        write(tmp_path / name / "wrists.urdf", robot(collisions))
        text = """
            model:
              robotname: wrists
              modelname: wrists
              input_models: {src: {basefile: wrists.urdf}}
              assemble: {model: src}
              reduce_meshes: 4
              export_config:
                - type: urdf
                  mesh_format: stl
            """
        sink = Diags()
        _compile(tmp_path / name, text, sink)
        found = [d.message for d in sink.diagnostics if d.code == "W0582"]
        if collisions:
            assert found == [f"mesh '{wrist}' of a collision of links 'l0', 'l1', 'l2' and 1 more is a "
                             "closed solid but not after reduce_meshes"]
        else:
            assert found == []
        sink.diagnostics[:] = [d for d in sink.diagnostics if d.code != "W0582"]
