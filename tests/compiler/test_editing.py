"""Model editing on real models: physical invariants checked with Pinocchio."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from lxml import etree

from mpc.ir import transforms as tf
from tests.backends.pin_compare import load, random_configurations
from tests.conftest import ERD, Diags, compile_file, write

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"


def _compile(tmp_path: Path, source: Path, sections: str, name: str = "talos") -> Path:
    spec = write(tmp_path / "edit.yml", f"""
        model:
          robotname: {name}
          modelname: {name}-edited
          input_models: {{src: {{basefile: "{source}"}}}}
          assemble: {{model: src}}
        """ + sections)
    sink = Diags()
    result = compile_file(spec, tmp_path / "out", sink)
    assert result.out is not None, sink.summary()
    return result.out / "urdf" / f"{name}.urdf"


def _frames(model: pin.Model, q: np.ndarray) -> dict[str, np.ndarray]:
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return {f.name: data.oMf[i].homogeneous.copy() for i, f in enumerate(model.frames)}


def test_removing_a_fixed_joint_keeps_mass_com_and_composite_inertia(tmp_path: Path) -> None:
    """The gripper's fixed base link merges into the wrist link."""
    out = _compile(tmp_path, TALOS, """
          joints:
            gripper_left_base_link_joint: {remove: true}
        """)
    a, b = load(TALOS), load(out)
    assert "gripper_left_base_link" not in {f.name for f in b.frames}
    assert abs(pin.computeTotalMass(a) - pin.computeTotalMass(b)) < 1e-12
    da, db = a.createData(), b.createData()
    for q in [pin.neutral(a), *random_configurations(a, 3, seed=2)]:
        np.testing.assert_allclose(pin.centerOfMass(a, da, q), pin.centerOfMass(b, db, q), atol=1e-12)
        np.testing.assert_allclose(pin.computeGeneralizedGravity(a, da, q),
                                   pin.computeGeneralizedGravity(b, db, q), atol=1e-11)
    # The composite spatial inertia of the body the link merged into (Pinocchio lumps fixed
    # children into their joint's body, so both models hold the merged body there).
    ja, jb = a.getJointId("arm_left_7_joint"), b.getJointId("arm_left_7_joint")
    np.testing.assert_allclose(a.inertias[ja].matrix(), b.inertias[jb].matrix(), atol=1e-12)


@pytest.mark.parametrize(("link", "joint", "xyz"), [
    ("arm_left_4_link", "arm_left_4_joint", (0.0, 0.03, 0.0)),  # revolute: along its axis only
    ("wrist_left_ft_tool_link", "wrist_left_tool_joint", (0.01, -0.02, 0.03)),  # fixed: any
])
def test_transform_frame_changes_no_other_frame_and_no_dynamics(
        tmp_path: Path, link: str, joint: str, xyz: tuple) -> None:
    out = _compile(tmp_path, TALOS, f"""
          frames:
            {link}:
              transform_frame: {{xyz: {list(xyz)}, rpy: [0.1, -0.2, 0.3]}}
        """)
    a, b = load(TALOS), load(out)
    T = tf.pose_to_matrix(xyz, (0.1, -0.2, 0.3))
    for q in random_configurations(a, 4, seed=9):
        fa, fb = _frames(a, q), _frames(b, q)
        for name, X in fa.items():
            expected = X @ T if name in (link, joint) else X
            np.testing.assert_allclose(fb[name], expected, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(pin.computeGeneralizedGravity(a, a.createData(), q),
                                   pin.computeGeneralizedGravity(b, b.createData(), q), atol=1e-12)
        np.testing.assert_allclose(pin.centerOfMass(a, a.createData(), q),
                                   pin.centerOfMass(b, b.createData(), q), atol=1e-12)


def test_transform_frame_off_a_revolute_axis_is_refused(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "edit.yml", f"""
        model:
          robotname: talos
          modelname: talos-edited
          input_models: {{src: {{basefile: "{TALOS}"}}}}
          assemble: {{model: src}}
          frames:
            arm_left_4_link:
              transform_frame: {{xyz: [0.01, 0, 0]}}
        """)
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0320")
    assert d.message == ("transform_frame of 'arm_left_4_link' would move the axis of revolute joint "
                         "'arm_left_4_joint' off its line and change the motion; translate the frame "
                         "only along the axis")
    assert (d.span.line, d.span.col) == (7, 5)


def test_transform_link_moves_exactly_its_subtree(tmp_path: Path) -> None:
    out = _compile(tmp_path, TALOS, """
          frames:
            arm_left_4_link:
              transform_link: {xyz: [0, 0, 0.05], rpy: [0, 0, 0.5]}
        """)
    a, b = load(TALOS), load(out)
    T = tf.pose_to_matrix((0, 0, 0.05), (0, 0, 0.5))
    q = pin.neutral(a)
    fa, fb = _frames(a, q), _frames(b, q)
    X_R4 = fa["arm_left_4_link"]
    below = {f.name for f in a.frames if f.name.startswith(("arm_left_4", "arm_left_5", "arm_left_6",
                                                            "arm_left_7", "gripper_left", "wrist_left"))}
    assert {"gripper_left_base_link", "arm_left_7_link"} <= below
    for name, X in fa.items():
        expected = X_R4 @ T @ np.linalg.inv(X_R4) @ X if name in below else X
        np.testing.assert_allclose(fb[name], expected, atol=1e-12, err_msg=name)
    assert abs(pin.computeTotalMass(a) - pin.computeTotalMass(b)) < 1e-12


def test_reparent_keeps_the_root_relative_transform(tmp_path: Path) -> None:
    out = _compile(tmp_path, TALOS, """
          frames:
            imu_link:
              reparent_to: torso_2_link
        """)
    a, b = load(TALOS), load(out)
    joint = next(j for j in etree.parse(str(out)).getroot().findall("joint")
                 if j.find("child").get("link") == "imu_link")
    assert joint.find("parent").get("link") == "torso_2_link"
    fa, fb = _frames(a, pin.neutral(a)), _frames(b, pin.neutral(b))
    for name, X in fa.items():
        np.testing.assert_allclose(fb[name], X, atol=1e-12, err_msg=name)


def test_estimated_com_of_a_box_mesh_is_the_box_centre(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(0.2, 0.1, 0.4))
    box.apply_translation((0.05, -0.03, 0.2))
    box.export(tmp_path / "box.stl")
    urdf = write(tmp_path / "boxy.urdf", """
        <robot name="boxy">
          <link name="base">
            <inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
            <collision><origin xyz="0 0 0.1"/><geometry><mesh filename="box.stl"/></geometry></collision>
          </link>
        </robot>
        """)
    out = _compile(tmp_path, urdf, """
          frames:
            $default: {estimate_missing_coms: true}
        """, name="boxy")
    origin = etree.parse(str(out)).getroot().find("link/inertial/origin")
    np.testing.assert_allclose([float(x) for x in origin.get("xyz").split()], [0.05, -0.03, 0.3],
                               atol=1e-12)


def test_joint_limits_with_units_and_defaults(tmp_path: Path) -> None:
    arm = ERD / "talos_data/robots/talos_left_arm.urdf"
    out = _compile(tmp_path, arm, """
          joints:
            $default: {eff: 99}
            $all: true
            arm_left_2_joint: {min: ["deg", -45], max: deg(45), vel: 2*pi, damping: 0.5}
        """, name="arm")
    joints = {j.get("name"): j for j in etree.parse(str(out)).getroot().findall("joint")}
    limit = joints["arm_left_2_joint"].find("limit")
    assert float(limit.get("lower")) == pytest.approx(-np.pi / 4, abs=1e-15)
    assert float(limit.get("upper")) == pytest.approx(np.pi / 4, abs=1e-15)
    assert float(limit.get("velocity")) == 2 * np.pi
    assert joints["arm_left_2_joint"].find("dynamics").get("damping") == "0.5"
    # $default fills only what is missing or zero: talos's efforts are set, so they stay.
    src = {j.get("name"): j for j in etree.parse(str(arm)).getroot().findall("joint")}
    assert limit.get("effort") == src["arm_left_2_joint"].find("limit").get("effort")


@pytest.mark.parametrize("model", ["solo_description/robots/solo12.urdf",
                                   "talos_data/robots/talos_reduced.urdf"])
def test_auto_bitmask(tmp_path: Path, model: str) -> None:
    """Pairs the rules keep apart share no bit, pairs that may collide share one, and links
    touching at the zero pose (checked independently with Pinocchio's geometry) never collide."""
    from mpc.backends import urdf as urdf_backend
    from mpc.core.diagnostics import Sink
    from mpc.ir.bitmask import never_colliding

    source = ERD / model
    out = _compile(tmp_path, source, """
          collisions:
            auto_bitmask: true
        """, name="robot")
    root = etree.parse(str(out)).getroot()
    assert root.find(".//collision/bitmask") is None  # URDF has no bitmasks; SMURF carries them
    mpc_robot = urdf_backend.read(source, Sink())
    assert mpc_robot is not None
    # Re-run the op on the IR to read the masks it sets.
    from mpc.core.span import Span
    from mpc.ir.ops import AutoBitmask, Effects

    op = AutoBitmask(span=Span("x"))
    sink = Sink()
    edited = op.apply(mpc_robot, Effects(sink, op))
    masks = {n: lk.collisions[0].bitmask for n, lk in edited.links.items() if lk.collisions}
    assert all(m is not None for m in masks.values())
    for pair in never_colliding(mpc_robot):
        a, b = sorted(pair)
        if a in masks and b in masks:
            assert masks[a] & masks[b] == 0, pair
    may = {frozenset(p) for p in edited.annotations["self_collision"]["may_collide"]}
    for pair in may:
        a, b = sorted(pair)
        assert masks[a] & masks[b], pair
    # Independent contact test at the neutral pose.
    pin_model = pin.buildModelFromUrdf(str(source))
    geom = pin.buildGeomFromUrdf(pin_model, str(source), pin.GeometryType.COLLISION,
                                 package_dirs=[str(ERD.parent.parent)])
    geom.addAllCollisionPairs()
    data, gdata = pin_model.createData(), pin.GeometryData(geom)
    pin.computeCollisions(pin_model, data, geom, gdata, pin.neutral(pin_model), False)
    touching = 0
    for k, cp in enumerate(geom.collisionPairs):
        if gdata.collisionResults[k].isCollision():
            a = pin_model.frames[geom.geometryObjects[cp.first].parentFrame].name
            b = pin_model.frames[geom.geometryObjects[cp.second].parentFrame].name
            if a != b and a in masks and b in masks:
                touching += 1
                assert masks[a] & masks[b] == 0, (a, b)
    assert touching > 0
    assert len(may) > 10


def test_make_root_keeps_the_multibody(tmp_path: Path) -> None:
    """With the left foot as root, every link keeps its pose relative to every other link,
    for any configuration: X_new(F) = X_old(L)⁻¹ · X_old(P) · A_P, A_P the frame move."""
    from mpc.backends import urdf as urdf_backend
    from mpc.core.diagnostics import Sink

    out = _compile(tmp_path, TALOS, """
          frames:
            leg_left_6_link:
              make_root: true
        """)
    old, new = pin.buildModelFromUrdf(str(TALOS)), pin.buildModelFromUrdf(str(out))
    ir_new = urdf_backend.read(out, Sink())
    assert ir_new is not None and ir_new.root == "leg_left_6_link"
    assert abs(pin.computeTotalMass(load(TALOS)) - pin.computeTotalMass(load(out))) < 1e-9
    ir_old = urdf_backend.read(TALOS, Sink())
    path = {"leg_left_6_link", "leg_left_5_link", "leg_left_4_link", "leg_left_3_link",
            "leg_left_2_link", "leg_left_1_link", "base_link"}
    for q_old in random_configurations(old, 3, seed=4):
        q_new = pin.neutral(new)
        for jid in range(1, old.njoints):
            nid = new.getJointId(old.names[jid])
            q_new[new.idx_qs[nid]] = q_old[old.idx_qs[jid]]
        fo, fn = _frames(old, q_old), _frames(new, q_new)
        X_L = fo["leg_left_6_link"]
        for name in ir_old.links:
            A = np.eye(4)
            if name in path and name != "leg_left_6_link":
                child = next(j for j in ir_old.joints.values() if j.parent == name and j.child in path)
                A = tf.pose_to_matrix(child.origin.xyz, child.origin.rpy)
            np.testing.assert_allclose(fn[name], np.linalg.inv(X_L) @ fo[name] @ A, atol=1e-9, err_msg=name)


def _convex(mesh: trimesh.Trimesh) -> float:
    """The largest distance of a vertex outside a face plane (≤ 0 for a convex mesh)."""
    normals, origins = mesh.face_normals, mesh.triangles[:, 0]
    return float(np.einsum("fk,fvk->fv", normals, mesh.vertices[None, :, :] - origins[:, None, :]).max())


def test_join_and_convex_collisions_are_convex_hulls(tmp_path: Path) -> None:
    """finger_edu's base link has four collision meshes: joined, they become one convex hull
    that contains them all; a `shape: convex` collision becomes its mesh's hull."""
    source = ERD / "finger_edu_description/robots/finger_edu.urdf"
    out = _compile(tmp_path, source, """
          collisions:
            finger_base_link: {join: true}
            finger_upper_link: {shape: convex}
        """, name="finger")
    root = etree.parse(str(out)).getroot()
    links = {lk.get("name"): lk for lk in root.findall("link")}
    [joined] = links["finger_base_link"].findall("collision")
    [hull] = links["finger_upper_link"].findall("collision")
    joined_file = joined.find("geometry/mesh").get("filename")
    assert joined_file.endswith("_joined_hull.stl") and hull.find("geometry/mesh").get("filename").endswith(
        "_hull.stl")
    for c in (joined, hull):
        mesh = trimesh.load(out.parent / c.find("geometry/mesh").get("filename"), force="mesh")
        assert mesh.volume > 0 and _convex(mesh) < 1e-9
    # The joined hull contains each part (scaled, placed), within the float32 precision of STL.
    from mpc.backends import urdf as urdf_backend
    from mpc.core.diagnostics import Sink
    from mpc.ir.kinematics import pose_matrix
    from mpc.ir.mesh_props import as_trimesh

    src = urdf_backend.read(source, Sink())
    parts = src.links["finger_base_link"].collisions
    X_first = np.linalg.inv(pose_matrix(parts[0].origin))
    joined_mesh = trimesh.load(out.parent / joined_file, force="mesh")
    for part in parts:
        piece = as_trimesh(part.geometry)
        piece.apply_transform(X_first @ pose_matrix(part.origin))
        normals, origins = joined_mesh.face_normals, joined_mesh.triangles[:, 0]
        outside = np.einsum("fk,fvk->fv", normals, piece.vertices[None, :, :] - origins[:, None, :]).max()
        assert outside < 1e-6


def test_uncovered_joints_get_serial_and_fixed_chains(tmp_path: Path) -> None:
    """With a submechanism over the shoulder only, the elbow becomes a serial chain and the
    fixed wrist joints a fixed chain; every joint is then covered exactly once."""
    from mpc.compiler.driver import Options, compile_model

    arm = ERD / "talos_data/robots/talos_left_arm.urdf"
    spec = write(tmp_path / "s.yml", f"""
        model:
          robotname: arm
          modelname: arm-sm
          input_models: {{src: {{basefile: "{arm}"}}}}
          assemble: {{model: src}}
          submechanisms:
            - name: shoulder
              type: serial
              jointnames_spanningtree: [arm_left_2_joint, arm_left_3_joint]
        """)
    result = compile_model(spec, Diags(), Options(out=tmp_path / "out"))
    robot = result.robot
    assert robot is not None
    made = {s.name: s.definition for s in robot.submechanisms}
    assert list(made) == ["shoulder", "serial_chain_arm_left_4_joint", "fixed_chain_wrist_left_ft_joint",
                          "serial_chain_gripper_left_joint"]
    assert made["serial_chain_arm_left_4_joint"]["jointnames"] == [
        "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"]
    covered = [j for d in made.values() for j in d.get("jointnames", d.get("jointnames_spanningtree", []))]
    assert sorted(covered) == sorted(robot.joints)
    for d in made.values():
        if d.get("auto_gen"):
            kinds = {robot.joints[j].type == "fixed" for j in d["jointnames"]}
            assert kinds == {d["type"] == "fixed"}


def test_convex_decomposition_makes_one_convex_collision_per_part(tmp_path: Path) -> None:
    ring = trimesh.creation.annulus(r_min=0.05, r_max=0.1, height=0.04, sections=12)
    ring.export(tmp_path / "ring.stl")
    urdf = write(tmp_path / "ringy.urdf", """
        <robot name="ringy">
          <link name="base">
            <collision name="ring"><geometry><mesh filename="ring.stl"/></geometry></collision>
          </link>
        </robot>
        """)
    out = _compile(tmp_path, urdf, """
          collisions:
            base: {shape: convex_decomposition}
        """, name="ringy")
    collisions = etree.parse(str(out)).getroot().findall("link/collision")
    assert len(collisions) >= 3  # a ring is far from convex
    assert [c.get("name") for c in collisions] == [f"ring_{i}" for i in range(len(collisions))]
    total = 0.0
    for c in collisions:
        part = trimesh.load(out.parent / c.find("geometry/mesh").get("filename"), force="mesh")
        assert _convex(part) < 1e-6 and part.volume > 0
        assert np.all(part.bounds[0] >= ring.bounds[0] - 0.01)
        assert np.all(part.bounds[1] <= ring.bounds[1] + 0.01)
        total += part.volume
    assert total == pytest.approx(ring.volume, rel=0.25)
