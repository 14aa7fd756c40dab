"""The usd export on small robots the tests write: each joint type with its frame, axis and
limits (degrees), a drive from a motor, filtered pairs from bitmasks, a mimic joint written
(NewtonMimicAPI, read by Newton) and one named in W0500, a loop closure as a spherical joint,
prim names made valid, both layouts, stage metadata, byte stability and usd-core's validators."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdPhysics, UsdShade, UsdValidation

from mpc.backends import urdf_reader, usd
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Severity, Sink
from mpc.core.span import Span
from mpc.ir.extras import CutJoint
from mpc.ir.program import UsdExport
from mpc.ir.robot import Pose
from tests.backends.newton_read import newton_reads
from tests.conftest import Diags, write

URDF = """\
<robot name="toy bot">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <inertial><mass value="2"/>
      <inertia ixx="0.1" ixy="0.01" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial>
    <visual><geometry><box size="0.2 0.3 0.1"/></geometry><material name="red"/></visual>
    <collision name="base_box"><geometry><box size="0.2 0.3 0.1"/></geometry></collision>
  </link>
  <link name="arm 1">
    <inertial><origin xyz="0 0 0.1" rpy="0 0.3 0"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial>
    <collision name="arm_cyl"><geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>
  </link>
  <link name="slider">
    <inertial><mass value="0.5"/>
      <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
    <collision name="slider_ball"><geometry><sphere radius="0.04"/></geometry></collision>
  </link>
  <link name="wheel">
    <inertial><mass value="0.3"/>
      <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="2e-3"/></inertial>
  </link>
  <link name="finger">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>
  <link name="pusher">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>
  <link name="tip"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm 1"/>
    <origin xyz="0.1 0 0.05" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1.2" upper="0.8" effort="30" velocity="2"/>
    <dynamics damping="0.5" friction="0.25"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="arm 1"/><child link="slider"/>
    <origin xyz="0 0 0.3"/><axis xyz="-1 0 0"/>
    <limit lower="-0.1" upper="0.2" effort="50" velocity="1"/>
  </joint>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <origin xyz="-0.1 0.15 0" rpy="0 0 1"/><axis xyz="0.6 0.8 0"/>
  </joint>
  <joint name="follow" type="revolute">
    <parent link="slider"/><child link="finger"/>
    <origin xyz="0 0.05 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/>
    <mimic joint="shoulder" multiplier="2" offset="0.1"/>
  </joint>
  <joint name="push" type="prismatic">
    <parent link="slider"/><child link="pusher"/>
    <origin xyz="0 -0.05 0"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.01" effort="1" velocity="1"/>
    <mimic joint="shoulder" multiplier="0.01"/>
  </joint>
  <joint name="weld" type="fixed">
    <parent link="finger"/><child link="tip"/><origin xyz="0 0 0.02"/>
  </joint>
</robot>
"""

DEFINITION = """\
model:
  robotname: toy
  modelname: toy-model
  input_models:
    toy:
      basefile: toy.urdf
  assemble:
    model: toy
  joints:
    shoulder:
      active: {p: 100, d: 2}
  collisions:
    base_box: {bitmask: 1}
    arm_cyl: {bitmask: 2}
    slider_ball: {bitmask: 3}
  export_config:
    - type: usd
    - type: usd
      layout: single
      filename_suffix: _single
"""
LEFT_OUT = ("the USD leaves out what it cannot hold: 1 mimic of or by a joint of another kind or without "
            "one degree of freedom")
DEG = 180 / math.pi


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("toy")
    write(folder / "toy.urdf", URDF)
    definition = write(folder / "toy.yml", DEFINITION)
    sink = Sink()
    result = compile_model(definition, sink, Options(out=folder / "out"))
    assert result.out is not None, [str(d) for d in sink.diagnostics]
    warnings = [d.message for d in sink.diagnostics if d.code == "W0500"]
    assert warnings == [LEFT_OUT, LEFT_OUT]
    assert [d for d in sink.diagnostics if d.code != "W0500"] == []
    return result.out


def _stage(built: Path, name: str = "toy.usda") -> Usd.Stage:
    stage = Usd.Stage.Open(str(built / "usd" / name))
    assert stage is not None
    return stage


@pytest.fixture(params=["toy.usda", "toy_single.usda"])
def stage(request: pytest.FixtureRequest, built: Path) -> Usd.Stage:
    return _stage(built, request.param)


def _world(stage: Usd.Stage, path: str) -> np.ndarray:
    """A prim's pose in the stage as a 4×4 column-vector matrix (USD's are row-vector)."""
    m = UsdGeom.Xformable(stage.GetPrimAtPath(path)).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    return np.array(m).T


def _quat(q: Gf.Quatf | Gf.Quatd) -> np.ndarray:
    """The rotation matrix of a USD quaternion (column vectors)."""
    return np.array(Gf.Matrix3d(Gf.Rotation(Gf.Quatd(q.GetReal(), Gf.Vec3d(q.GetImaginary()))))).T


def _joint_frames(stage: Usd.Stage, path: str) -> tuple[np.ndarray, np.ndarray]:
    """A joint's frame in the world as each side places it (body0's, body1's)."""
    j = UsdPhysics.Joint(stage.GetPrimAtPath(path))
    out = []
    for rel, pos, rot in ((j.GetBody0Rel(), j.GetLocalPos0Attr(), j.GetLocalRot0Attr()),
                          (j.GetBody1Rel(), j.GetLocalPos1Attr(), j.GetLocalRot1Attr())):
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = _quat(rot.Get()), np.array(pos.Get())
        out.append(_world(stage, str(rel.GetTargets()[0])) @ X)
    return out[0], out[1]


def test_the_stage_says_metres_kilograms_z_up_and_its_default_prim(stage: Usd.Stage) -> None:
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert UsdPhysics.GetStageKilogramsPerUnit(stage) == 1.0
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert stage.GetDefaultPrim().GetPath() == Sdf.Path("/toy")
    assert stage.GetDefaultPrim().HasAPI(UsdPhysics.ArticulationRootAPI)


def test_the_layered_layout_is_an_interface_with_a_payload_of_three_layers(built: Path) -> None:
    folder = built / "usd"
    assert sorted(str(p.relative_to(folder)) for p in folder.rglob("*")) == [
        "toy.usda", "toy_payload", "toy_payload/contents.usda", "toy_payload/geometry.usdc",
        "toy_payload/materials.usda", "toy_payload/physics.usda", "toy_single.usda"]
    interface = Sdf.Layer.FindOrOpen(str(folder / "toy.usda"))
    assert [p.assetPath for p in interface.GetPrimAtPath("/toy").payloadList.prependedItems] == [
        "./toy_payload/contents.usda"]
    contents = Sdf.Layer.FindOrOpen(str(folder / "toy_payload/contents.usda"))
    assert list(contents.subLayerPaths) == ["./physics.usda", "./materials.usda", "./geometry.usdc"]
    physics = (folder / "toy_payload/physics.usda").read_text()
    assert (folder / "toy_payload/geometry.usdc").read_bytes().startswith(b"PXR-USDC")
    geometry = Sdf.Layer.FindOrOpen(str(folder / "toy_payload/geometry.usdc")).ExportToString()
    assert "PhysicsRevoluteJoint" in physics and "def Mesh" not in physics and "Cube" not in physics
    assert "Physics" not in geometry and "Material" not in geometry


def test_both_layouts_compose_the_same_prims(built: Path) -> None:
    def prims(stage: Usd.Stage) -> dict[str, dict[str, object]]:
        return {str(p.GetPath()): {a.GetName(): a.Get() for a in p.GetAttributes()}
                | {"schemas": tuple(p.GetAppliedSchemas()), "type": p.GetTypeName()}
                for p in stage.Traverse()}

    assert prims(_stage(built)) == prims(_stage(built, "toy_single.usda"))


def test_a_rebuild_gives_the_same_bytes(built: Path, tmp_path: Path) -> None:
    """Built anew (`force`: not the kept build), the text and the crate alike."""
    folder = built.parent
    sink = Sink()
    result = compile_model(folder / "toy.yml", sink, Options(out=tmp_path / "again", force=True))
    assert result.out is not None
    written = sorted((built / "usd").rglob("*.usd?"))
    assert len(written) == 6
    for path in written:
        assert (result.out / "usd" / path.relative_to(built / "usd")).read_bytes() == path.read_bytes()


def test_prim_names_are_made_valid_and_keep_the_original(stage: Usd.Stage) -> None:
    arm = stage.GetPrimAtPath("/toy/arm_1")
    assert Tf.MakeValidIdentifier("arm 1") == "arm_1"
    assert arm.IsValid() and arm.GetAttribute("mpc:name").Get() == "arm 1"
    assert stage.GetPrimAtPath("/toy/joints/shoulder").GetAttribute("mpc:name").Get() == "shoulder"


def test_joint_types_frames_axes_and_limits_in_degrees(stage: Usd.Stage) -> None:
    robot = urdf_reader.read(Path(_source(stage)), Sink())
    assert robot is not None
    from mpc.ir.kinematics import links_in_root, pose_matrix

    X = links_in_root(robot)
    kinds = {"shoulder": UsdPhysics.RevoluteJoint, "slide": UsdPhysics.PrismaticJoint,
             "spin": UsdPhysics.RevoluteJoint, "follow": UsdPhysics.RevoluteJoint,
             "push": UsdPhysics.PrismaticJoint, "weld": UsdPhysics.FixedJoint}
    for name, kind in kinds.items():
        j = robot.joints[name]
        prim = stage.GetPrimAtPath(f"/toy/joints/{name}")
        assert prim.IsA(kind), name
        on0, on1 = _joint_frames(stage, str(prim.GetPath()))
        expected = X[j.parent] @ pose_matrix(j.origin)
        np.testing.assert_allclose(on0[:3, 3], expected[:3, 3], atol=1e-7, err_msg=name)
        np.testing.assert_allclose(on1, on0, atol=1e-6, err_msg=name)
        if kind is UsdPhysics.FixedJoint:
            continue
        axis = {"X": 0, "Y": 1, "Z": 2}[prim.GetAttribute("physics:axis").Get()]
        direction = np.asarray(j.axis) / np.linalg.norm(j.axis)
        np.testing.assert_allclose(on0[:3, axis], expected[:3, :3] @ direction, atol=1e-6, err_msg=name)
    limits = {n: (stage.GetPrimAtPath(f"/toy/joints/{n}").GetAttribute("physics:lowerLimit").Get(),
                  stage.GetPrimAtPath(f"/toy/joints/{n}").GetAttribute("physics:upperLimit").Get())
              for n in ("shoulder", "slide", "spin")}
    assert limits["shoulder"] == pytest.approx((-1.2 * DEG, 0.8 * DEG), rel=1e-6)
    assert limits["slide"] == pytest.approx((-0.1, 0.2), rel=1e-6)
    assert not stage.GetPrimAtPath("/toy/joints/spin").GetAttribute("physics:lowerLimit").HasAuthoredValue()


def _source(stage: Usd.Stage) -> str:
    return str(Path(stage.GetRootLayer().realPath).parents[2] / "toy.urdf")


def test_a_motor_is_a_drive_per_degree(stage: Usd.Stage) -> None:
    prim = stage.GetPrimAtPath("/toy/joints/shoulder")
    drive = UsdPhysics.DriveAPI.Get(prim, "angular")
    assert prim.HasAPI(UsdPhysics.DriveAPI, "angular")
    assert drive.GetTypeAttr().Get() == "force"
    assert drive.GetStiffnessAttr().Get() == pytest.approx(100 / DEG, rel=1e-6)
    assert drive.GetDampingAttr().Get() == pytest.approx(2 / DEG, rel=1e-6)
    assert drive.GetMaxForceAttr().Get() == pytest.approx(30)
    assert not stage.GetPrimAtPath("/toy/joints/slide").HasAPI(UsdPhysics.DriveAPI, "linear")


def test_bitmasks_become_filtered_pairs(stage: Usd.Stage) -> None:
    """base (1) and arm (2) share no bit; the slider (3) shares one with each."""
    filtered = {str(p.GetPath()): [str(t) for t in UsdPhysics.FilteredPairsAPI(p).GetFilteredPairsRel()
                                   .GetTargets()]
                for p in stage.Traverse() if p.HasAPI(UsdPhysics.FilteredPairsAPI)}
    assert filtered == {"/toy/base": ["/toy/arm_1"]}


def test_mass_properties_and_collision_shapes(stage: Usd.Stage) -> None:
    arm = UsdPhysics.MassAPI(stage.GetPrimAtPath("/toy/arm_1"))
    assert arm.GetMassAttr().Get() == 1.0
    assert tuple(arm.GetCenterOfMassAttr().Get()) == pytest.approx((0, 0, 0.1))
    R = _quat(arm.GetPrincipalAxesAttr().Get())
    inertia = R @ np.diag(arm.GetDiagonalInertiaAttr().Get()) @ R.T
    from mpc.ir import transforms as tf

    R0 = tf.rpy_to_matrix((0, 0.3, 0))
    np.testing.assert_allclose(inertia, R0 @ np.diag([0.01, 0.02, 0.015]) @ R0.T, atol=1e-8)
    tip = UsdPhysics.MassAPI(stage.GetPrimAtPath("/toy/tip"))
    assert tip.GetMassAttr().Get() == 0 and not tip.GetDiagonalInertiaAttr().HasAuthoredValue()
    shapes = {str(p.GetPath()): p.GetTypeName() for p in stage.Traverse()
              if p.HasAPI(UsdPhysics.CollisionAPI)}
    assert shapes == {"/toy/base/collisions/base_box": "Cube", "/toy/arm_1/collisions/arm_cyl": "Cylinder",
                      "/toy/slider/collisions/slider_ball": "Sphere"}
    box = stage.GetPrimAtPath("/toy/base/collisions/base_box")
    assert UsdGeom.Imageable(box).GetPurposeAttr().Get() == UsdGeom.Tokens.guide
    bound = UsdGeom.Imageable(box).ComputeLocalBound(Usd.TimeCode.Default(), UsdGeom.Tokens.guide)
    np.testing.assert_allclose(np.array(bound.ComputeAlignedRange().GetSize()), [0.2, 0.3, 0.1], atol=1e-12)


def test_visual_colours_are_preview_surfaces(stage: Usd.Stage) -> None:
    visual = stage.GetPrimAtPath("/toy/base/visuals/base_visual")
    material, _ = UsdShade.MaterialBindingAPI(visual).ComputeBoundMaterial()
    assert material.GetPath() == Sdf.Path("/toy/materials/red")
    shader = UsdShade.Shader(stage.GetPrimAtPath("/toy/materials/red/PreviewSurface"))
    assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
    assert tuple(shader.GetInput("diffuseColor").Get()) == (1, 0, 0)


def test_a_mimic_joint_is_newtons_mimic_and_newton_reads_it(built: Path) -> None:
    stage = _stage(built)
    prim = stage.GetPrimAtPath("/toy/joints/follow")
    assert "NewtonMimicAPI" in prim.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
    leader = prim.GetRelationship("newton:mimicJoint").GetTargets()
    assert [str(t) for t in leader] == ["/toy/joints/shoulder"]
    assert prim.GetAttribute("newton:mimicCoef0").Get() == pytest.approx(0.1 * DEG, rel=1e-6)
    assert prim.GetAttribute("newton:mimicCoef1").Get() == 2
    push = stage.GetPrimAtPath("/toy/joints/push")
    assert "NewtonMimicAPI" not in push.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
    read = newton_reads([built / "usd" / "toy.usda"])[str(built / "usd" / "toy.usda")]
    assert read["joints"]["/toy/joints/follow"]["mimic"] == "/toy/joints/shoulder"
    assert read["joints"]["/toy/joints/follow"]["coeffs"] == pytest.approx([0.1, 2.0], rel=1e-6)
    assert read["joints"]["/toy/joints/push"]["mimic"] is None
    assert read["velocity_limits"]["/toy/joints/shoulder"] == pytest.approx(2, rel=1e-6)
    assert read["velocity_limits"]["/toy/joints/slide"] == pytest.approx(1, rel=1e-6)
    assert read["frictions"]["/toy/joints/shoulder"] == pytest.approx(0.25, rel=1e-6)


def test_velocity_limits_and_dynamics_are_newtons_joint_attributes(stage: Usd.Stage) -> None:
    """NewtonJointAPI, in its units: degrees on a rotational joint."""
    shoulder, slide = (stage.GetPrimAtPath(f"/toy/joints/{n}") for n in ("shoulder", "slide"))
    assert "NewtonJointAPI" in shoulder.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
    assert shoulder.GetAttribute("newton:velocityLimit").Get() == pytest.approx(2 * DEG, rel=1e-6)
    assert shoulder.GetAttribute("newton:damping").Get() == pytest.approx(0.5 / DEG, rel=1e-6)
    assert shoulder.GetAttribute("newton:friction").Get() == pytest.approx(0.25, rel=1e-6)
    assert slide.GetAttribute("newton:velocityLimit").Get() == pytest.approx(1, rel=1e-6)
    assert not slide.GetAttribute("newton:damping").HasAuthoredValue()


def test_usd_cores_validators_report_nothing(built: Path) -> None:
    context = UsdValidation.ValidationContext(UsdValidation.ValidationRegistry().GetOrLoadAllValidators())
    for name in ("toy.usda", "toy_single.usda"):
        errors = context.Validate(_stage(built, name))
        assert [(e.GetName(), e.GetMessage()) for e in errors] == []


def test_a_ball_loop_closure_is_a_spherical_joint_outside_the_articulation(tmp_path: Path,
                                                                          diags: Diags) -> None:
    write(tmp_path / "toy.urdf", URDF)
    robot = urdf_reader.read(tmp_path / "toy.urdf", Sink())
    assert robot is not None
    from mpc.ir.kinematics import links_in_root, matrix_pose

    X = links_in_root(robot)
    closed = matrix_pose(np.linalg.inv(X["wheel"]) @ X["pusher"])  # the loop closes at q = 0
    cuts = {"loop": CutJoint(name="loop", type="ball", parent="wheel", child="pusher", origin=closed),
            "slot": CutJoint(name="slot", type="prismatic", parent="wheel", child="finger",
                             origin=Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))}
    robot = replace(robot, cut_joints=cuts)
    usd.emit(robot, UsdExport(span=Span("toy.yml", 1, 1), layout="single"), tmp_path, diags)
    warning = diags.take("W0500", Severity.WARNING)
    assert "prismatic cut joint 'slot' (no UsdPhysics joint holds it)" in warning.message
    stage = Usd.Stage.Open(str(tmp_path / "usd" / "toy bot.usda"))
    prim = stage.GetPrimAtPath("/toy_bot/joints/loop")
    assert prim.IsA(UsdPhysics.SphericalJoint)
    assert UsdPhysics.Joint(prim).GetExcludeFromArticulationAttr().Get() is True
    on0, on1 = _joint_frames(stage, "/toy_bot/joints/loop")
    np.testing.assert_allclose(on0, on1, atol=1e-6)
    np.testing.assert_allclose(on1[:3, 3], X["pusher"][:3, 3], atol=1e-7)
    assert not stage.GetPrimAtPath("/toy_bot/joints/slot").IsValid()


def test_an_inertial_that_is_no_number_is_refused(tmp_path: Path, diags: Diags) -> None:
    """A definition's `.inf` or an overflowing product (URDF readers refuse them in a file)."""
    write(tmp_path / "toy.urdf", URDF)
    robot = urdf_reader.read(tmp_path / "toy.urdf", Sink())
    assert robot is not None and robot.links["slider"].inertial is not None
    slider = replace(robot.links["slider"], inertial=replace(robot.links["slider"].inertial, mass=math.inf))
    robot = replace(robot, links={**robot.links, "slider": slider})
    usd.emit(robot, UsdExport(span=Span("toy.yml", 1, 1)), tmp_path, diags)
    error = diags.take_error("E0587")
    assert error.message == ("link 'slider' has an inertial UsdPhysics cannot hold: its mass, inertia or "
                             "centre of mass holds a number that is not finite; no USD is written")
    assert (error.span.file, error.span.line) == (str(tmp_path / "toy.urdf"), 14)
    assert not (tmp_path / "usd").exists()


def test_an_inertial_beyond_32_bit_floats_is_refused(tmp_path: Path, diags: Diags) -> None:
    """UsdPhysics keeps masses, moments and centres of mass in 32-bit floats: a mass of 1e308
    (an MJCF's `boundmass`, found by the fuzz run) was written as `inf`."""
    write(tmp_path / "toy.urdf", URDF.replace('<mass value="0.5"/>', '<mass value="1e308"/>', 1))
    robot = urdf_reader.read(tmp_path / "toy.urdf", Sink())
    assert robot is not None
    usd.emit(robot, UsdExport(span=Span("toy.yml", 1, 1)), tmp_path, diags)
    error = diags.take_error("E0587")
    assert error.message.endswith(
        ": its mass, principal moments or centre of mass hold a number beyond ±3.4e38, the largest of the "
        "32-bit floats UsdPhysics keeps them in; no USD is written")
    assert not (tmp_path / "usd").exists()


def test_a_number_the_usd_would_hold_as_infinite_is_refused(tmp_path: Path, diags: Diags) -> None:
    """Any 32-bit float of the stage beyond ±3.4e38 (here a joint's origin at 1e39 m, its
    localPos0) is E0589, and nothing is written: usd-core writes such a number as `inf`."""
    write(tmp_path / "toy.urdf", URDF.replace('<origin xyz="0.1 0 0.05"', '<origin xyz="0.1 0 1e39"', 1))
    robot = urdf_reader.read(tmp_path / "toy.urdf", Sink())
    assert robot is not None
    usd.emit(robot, UsdExport(span=Span("toy.yml", 1, 1), layout="single"), tmp_path, diags)
    error = diags.take_error("E0589")
    assert error.message.startswith("the USD would hold a number that is not finite, beyond ±3.4e38 (the "
                                    "32-bit floats of UsdGeom and UsdPhysics): 'inf' in line ")
    assert error.message.endswith(" of 'toy bot.usda'; no USD is written")
    diags.take("W0500", Severity.WARNING)  # the toy's mimic, as in every USD of it
    assert not (tmp_path / "usd").exists()


def test_a_mesh_point_the_usd_would_hold_as_infinite_is_refused(tmp_path: Path) -> None:
    """A mesh's points are 32-bit floats in UsdGeom: an OBJ corner at 1e39 m is E0589 naming the
    mesh, and no USD is written (the URDF export of the same model writes it as it is)."""
    write(tmp_path / "meshes/far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e39\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    write(tmp_path / "far.urdf", """
        <robot name="far"><link name="base"><visual><geometry><mesh filename="meshes/far.obj"/>
        </geometry></visual></link></robot>""")
    definition = write(tmp_path / "far.yml", """
        model:
          robotname: far
          modelname: far
          input_models: {far: {basefile: far.urdf}}
          assemble: {model: far}
          export_config:
            - {type: usd, layout: single}
        """)
    sink = Sink()
    assert compile_model(definition, sink, Options(out=tmp_path / "out")).out is None
    [error] = [d for d in sink.diagnostics if d.severity is Severity.ERROR]
    assert error.code == "E0589"
    assert error.message == (
        "the USD would hold a number that is not finite, beyond ±3.4e38 (the 32-bit floats of UsdGeom and "
        f"UsdPhysics): a point of mesh '{tmp_path}/meshes/far.obj'; no USD is written")
    assert not (tmp_path / "out").exists()


MESHES = """\
<robot name="meshy">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
    <visual><geometry><mesh filename="meshes/tetra.stl" scale="2 2 2"/></geometry></visual>
    <collision name="plain"><geometry><mesh filename="meshes/tetra.stl"/></geometry></collision>
    <collision name="hulled"><geometry><mesh filename="meshes/tetra.stl"/></geometry></collision>
    <collision name="split"><geometry><mesh filename="meshes/tetra.stl"/></geometry></collision>
  </link>
</robot>
"""


def test_mesh_collisions_take_the_approximation_the_definition_implies(tmp_path: Path) -> None:
    """`shape: convex` and the parts of `convex_decomposition` are convex: convexHull; a mesh
    left as it is: none. The visual's triangles are the STL's, its scale the prim's."""
    from tests.fixtures import tetra_stl

    tetra_stl(tmp_path / "meshes" / "tetra.stl")
    write(tmp_path / "meshy.urdf", MESHES)
    definition = write(tmp_path / "meshy.yml", """
        model:
          robotname: meshy
          modelname: meshy-model
          input_models: {meshy: {basefile: meshy.urdf}}
          assemble: {model: meshy}
          collisions:
            hulled: {shape: convex}
            split: {shape: convex_decomposition}
          export_config:
            - {type: usd, layout: single}
        """)
    sink = Sink()
    result = compile_model(definition, sink, Options(out=tmp_path / "out"))
    assert result.out is not None, [str(d) for d in sink.diagnostics]
    stage = Usd.Stage.Open(str(result.out / "usd" / "meshy.usda"))
    found = {p.GetName(): UsdPhysics.MeshCollisionAPI(p).GetApproximationAttr().Get()
             for p in stage.Traverse() if p.HasAPI(UsdPhysics.MeshCollisionAPI)}
    assert found == {"plain": "none", "hulled": "convexHull", "split_0": "convexHull"}
    visual = UsdGeom.Mesh(stage.GetPrimAtPath("/meshy/base/visuals/base_visual"))
    assert list(visual.GetFaceVertexCountsAttr().Get()) == [3, 3, 3, 3]
    points = np.array(visual.GetPointsAttr().Get())
    assert {tuple(round(float(c), 6) for c in p) for p in points} == {
        (0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)}
    assert [op.GetOpName() for op in visual.GetOrderedXformOps()] == ["xformOp:scale"]
    assert tuple(visual.GetPrim().GetAttribute("xformOp:scale").Get()) == (2, 2, 2)


def test_a_ply_without_vertices_reads_as_an_empty_mesh() -> None:
    """The PLY reader of the usd export: a mesh of no vertices has no extent (not an error)."""
    from mpc.backends.usd_meshes import read_ply

    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
              b"property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n")
    empty = read_ply(header)
    assert empty is not None and empty.points.shape == (0, 3) and empty.extent == ((), ())
