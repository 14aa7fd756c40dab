"""MJCF input models (backends/mjcf_reader.py): one test per MuJoCo construct, on small MJCF
files written here, and physical equality with MuJoCo's compiled original through mpc's URDF
(Pinocchio) and mpc's MJCF (MuJoCo)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from mpc.backends import mjcf_reader
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Severity
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere
from mpc.ir.robot import Robot
from tests.backends.mjcf_compare import assert_mjcf_matches, assert_urdf_matches
from tests.conftest import Diags, write

ARM = """
<mujoco model="arm">
  <compiler angle="degree" autolimits="true"/>
  <default>
    <joint damping="0.5" armature="0.01"/>
    <default class="visual"><geom contype="0" conaffinity="0" group="2"/></default>
    <default class="collision"><geom group="3"/></default>
  </default>
  <worldbody>
    <body name="base" pos="0 0 0.1">
      <geom type="box" size="0.1 0.1 0.05" mass="2"/>
      <body name="l1" pos="0 0 0.1" euler="0 0 30">
        <joint name="j1" axis="0 0 1" range="-90 90" pos="0.02 0 0"/>
        <geom class="collision" type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/>
        <geom class="visual" type="sphere" size="0.05" rgba="1 0 0 1"/>
        <site name="tip" pos="0 0 0.3"/>
        <body name="l2" pos="0 0 0.3" quat="0.9 0.1 0.3 0">
          <joint name="j2" type="slide" axis="0 1 0" range="-0.1 0.1" frictionloss="0.2"/>
          <geom type="cylinder" size="0.02 0.1" pos="0 0 0.1"/>
          <body name="l3" pos="0.1 0 0.2">
            <joint name="j3" axis="1 1 0" pos="0 0.05 0"/>
            <geom type="box" size="0.02 0.03 0.04" pos="0.05 0 0" euler="10 20 30"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><position name="m1" joint="j1" kp="10"/><motor name="m3" joint="j3" ctrlrange="-1 1"/></actuator>
  <keyframe><key name="home" qpos="0.3 0.05 0.1"/></keyframe>
</mujoco>
"""


def _read(path: Path, diags: Diags) -> Robot | None:
    return mjcf_reader.read(path, diags)


def _compile(tmp_path: Path, xml: str, diags: Diags, exports: tuple[str, ...] = ("urdf", "mjcf"),
             name: str = "robot.xml") -> Path:
    write(tmp_path / name, xml)
    entries = "".join(f"    - type: {e}\n" for e in exports)
    (tmp_path / "robot.yml").write_text(f"""model:
  robotname: r
  modelname: r-model
  input_models:
    base:
      basefile: "{name}"
  assemble:
    model: base
  export_config:
{entries}""")
    result = compile_model(tmp_path / "robot.yml", diags, Options(out=tmp_path / "out"))
    assert not diags.has_errors(), diags.summary()
    assert result is not None
    return tmp_path / "out"


def test_bodies_joints_and_frames(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "arm.xml", ARM), diags)
    assert robot is not None and robot.root == "base"  # the one top body: the root, as in URDF
    assert set(robot.links) == {"base", "l1", "l2", "l3", "tip"}
    j1 = robot.joints["j1"]
    assert (j1.type, j1.parent, j1.child, j1.axis) == ("revolute", "base", "l1", (0.0, 0.0, 1.0))
    # degrees → radians, as MuJoCo compiles them; the joint frame at its anchor (pos)
    assert (j1.limit.lower, j1.limit.upper) == pytest.approx((-np.pi / 2, np.pi / 2), abs=1e-15)
    np.testing.assert_allclose(j1.origin.xyz, (0.02 * np.cos(np.pi / 6), 0.02 * np.sin(np.pi / 6), 0.1),
                               atol=1e-15)
    assert (j1.dynamics.damping, j1.annotations) == (0.5, {"armature": 0.01})
    j2 = robot.joints["j2"]
    assert (j2.type, j2.limit.lower, j2.limit.upper, j2.dynamics.friction) == ("prismatic", -0.1, 0.1, 0.2)
    assert robot.joints["j3"].type == "continuous"
    assert (robot.joints["tip_fixed"].parent, robot.joints["tip_fixed"].type) == ("l1", "fixed")


def test_geoms_become_visuals_and_collisions(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "arm.xml", ARM), diags)
    l1 = robot.links["l1"]
    # group 3 collides only; contype = conaffinity = 0 is visual only; a capsule is a cylinder
    # and two spheres
    assert [type(c.geometry) for c in l1.collisions] == [Cylinder, Sphere, Sphere]
    assert [type(v.geometry) for v in l1.visuals] == [Sphere]
    assert robot.materials[l1.visuals[0].material].rgba == (1.0, 0.0, 0.0, 1.0)
    base = robot.links["base"]  # a default geom collides and shows
    assert [type(v.geometry) for v in base.visuals] == [Box] == [type(c.geometry) for c in base.collisions]
    assert base.visuals[0].geometry.size == (0.2, 0.2, 0.1)


def test_inertials_from_the_compiled_model(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "arm.xml", ARM), diags)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml"))
    assert robot.links["base"].inertial.mass == 2.0
    assert sum(lk.inertial.mass for lk in robot.links.values() if lk.inertial) == pytest.approx(
        float(np.sum(model.body_mass)), abs=1e-12)


def test_actuators_keyframes(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "arm.xml", ARM), diags)
    assert robot.motors["m1"].joint == "j1"
    assert robot.motors["m1"].settings == {"type": "position", "p": 10.0, "d": -0.0}
    assert robot.motors["m3"].settings == {"type": "force", "gear": 1.0, "minValue": -1.0, "maxValue": 1.0}
    assert robot.poses == {"home": {"j1": 0.3, "j2": 0.05, "j3": 0.1}}


def test_physically_equal_through_urdf_and_mjcf(tmp_path: Path, diags: Diags) -> None:
    out = _compile(tmp_path, ARM, diags)
    diags.take("W0500", Severity.WARNING)  # the MJCF leaves out the pose's annotations …
    original = mujoco.MjModel.from_xml_path(str(tmp_path / "robot.xml"))
    assert_urdf_matches(original, out / "urdf" / "r.urdf")
    assert_mjcf_matches(original, out / "mjcf" / "r.xml")


def test_a_free_joint_makes_a_floating_root(tmp_path: Path, diags: Diags) -> None:
    xml = """
    <mujoco model="f">
      <worldbody>
        <geom name="floor" type="plane" size="1 1 0.1"/>
        <body name="torso" pos="0 0 1"><freejoint/><geom type="sphere" size="0.1"/>
          <body name="leg" pos="0 0 -0.2"><joint name="hip" axis="0 1 0" range="-1 1"/>
            <geom type="capsule" size="0.05" fromto="0 0 0 0 0 -0.3"/></body>
        </body>
      </worldbody>
    </mujoco>"""
    robot = _read(write(tmp_path / "f.xml", xml), diags)
    w = diags.take("W0440", Severity.WARNING)
    assert w.message == (f"'{tmp_path / 'f.xml'}' holds what mpc's robot model cannot: "
                         "worldbody geom ×1; left out")
    assert robot.root == "torso" and "world" not in robot.links
    out = _compile(tmp_path, xml, diags, name="f.xml")
    diags.take("W0440", Severity.WARNING)
    diags.take("W0500", Severity.WARNING)  # MJCF has no velocity limits
    original = mujoco.MjModel.from_xml_path(str(tmp_path / "f.xml"))
    assert_urdf_matches(original, out / "urdf" / "r.urdf")
    assert_mjcf_matches(original, out / "mjcf" / "r.xml")


def test_several_joints_in_one_body_become_a_chain(tmp_path: Path, diags: Diags) -> None:
    xml = """
    <mujoco model="c">
      <worldbody><body name="a" pos="0 0 1">
        <joint name="x" axis="1 0 0" pos="0 0 0.1" range="-1 1"/>
        <joint name="y" axis="0 1 0" pos="0 0.2 0"/>
        <joint name="z" type="slide" axis="0 0 1" range="0 0.5"/>
        <geom type="box" size="0.1 0.2 0.3" pos="0.1 0 0"/>
      </body></worldbody>
    </mujoco>"""
    robot = _read(write(tmp_path / "c.xml", xml), diags)
    assert [(j.parent, j.child) for j in robot.joints.values()] == [
        ("world", "a__x"), ("a__x", "a__y"), ("a__y", "a")]
    out = _compile(tmp_path, xml, diags, name="c.xml")
    diags.take("W0500", Severity.WARNING)  # MJCF has no velocity limits
    original = mujoco.MjModel.from_xml_path(str(tmp_path / "c.xml"))
    assert_urdf_matches(original, out / "urdf" / "r.urdf")
    # MuJoCo refuses a moving body without mass: the chain's joints go back into one body
    assert_mjcf_matches(original, out / "mjcf" / "r.xml")
    written = mujoco.MjModel.from_xml_path(str(out / "mjcf" / "r.xml"))
    assert [written.body(b).name for b in range(written.nbody)] == ["world", "a"]


def test_meshes_keep_their_files_scale_and_refpos(tmp_path: Path, diags: Diags) -> None:
    (tmp_path / "assets").mkdir()
    box = trimesh.creation.box((0.1, 0.2, 0.3)).apply_translation((0.05, 0.0, 0.0))
    box.export(tmp_path / "assets" / "part.stl")
    xml = """
    <mujoco model="m">
      <compiler meshdir="assets"/>
      <asset><mesh name="part" file="part.stl" scale="2 1 1" refpos="0.01 0.02 0" refquat="1 0 0 1"/></asset>
      <worldbody><body name="a"><joint name="j" axis="0 0 1"/>
        <geom type="mesh" mesh="part" pos="0.1 0.2 0.3" euler="0.1 0.2 0.3"/></body></worldbody>
    </mujoco>"""
    robot = _read(write(tmp_path / "m.xml", xml), diags)
    visual = robot.links["a"].visuals[0]
    assert isinstance(visual.geometry, Mesh)
    # refquat turns the file a quarter about z: the file's y axis is scaled by 2
    assert (visual.geometry.source.uri, visual.geometry.scale) == ("assets/part.stl", (1.0, 2.0, 1.0))
    # The file's vertices, scaled and placed by the visual's origin, are where MuJoCo puts them.
    from mpc.ir.kinematics import pose_matrix

    model = mujoco.MjModel.from_xml_path(str(tmp_path / "m.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    ours = trimesh.load(tmp_path / "assets" / "part.stl").vertices * visual.geometry.scale
    X = pose_matrix(visual.origin)
    ours = ours @ X[:3, :3].T + X[:3, 3]
    theirs = model.mesh_vert @ data.geom_xmat[0].reshape(3, 3).T + data.geom_xpos[0]
    assert np.allclose(np.sort(ours, axis=0), np.sort(theirs, axis=0), atol=1e-6)


def test_includes_and_default_classes(tmp_path: Path, diags: Diags) -> None:
    write(tmp_path / "parts" / "leg.xml", """
        <mujoco><body name="leg" pos="0 0 -0.5"><joint name="knee" class="bent"/>
          <geom type="sphere" size="0.1"/></body></mujoco>""")
    robot = _read(write(tmp_path / "r.xml", """
        <mujoco model="r">
          <default><default class="bent"><joint axis="0 1 0" range="-0.5 0.5"/></default></default>
          <worldbody><body name="hip"><geom type="sphere" size="0.1"/>
            <include file="parts/leg.xml"/></body></worldbody>
        </mujoco>"""), diags)
    knee = robot.joints["knee"]  # MJCF's angles are in degrees unless the compiler says radian
    assert (knee.axis, knee.limit.lower, knee.limit.upper) == ((0.0, 1.0, 0.0), -np.pi / 360, np.pi / 360)


def test_what_the_ir_cannot_hold_is_one_warning(tmp_path: Path, diags: Diags) -> None:
    path = write(tmp_path / "w.xml", """
        <mujoco model="w">
          <asset><texture name="t" type="2d" builtin="checker" width="8" height="8"/></asset>
          <worldbody><body name="a"><joint name="j" type="ball"/><geom type="ellipsoid" size="0.1 0.2 0.3"/>
            <site name="s"/></body>
            <body name="b" pos="1 0 0"><joint name="k" stiffness="2" springref="0.1"/>
              <geom type="sphere" size="0.1"/>
              <site name="t"/></body>
          </worldbody>
          <tendon><spatial name="t1"><site site="s"/><site site="t"/></spatial></tendon>
          <sensor><jointpos joint="k"/><touch site="s"/></sensor>
          <custom><numeric name="n" data="1"/></custom>
        </mujoco>""")
    robot = _read(path, diags)
    w = diags.take("W0440", Severity.WARNING)
    assert w.message == (f"'{path}' holds what mpc's robot model cannot: ball joint ×1, custom numeric ×1, "
                         "ellipsoid ×1, sensor ×2, tendon ×1, texture ×1; left out")
    assert (w.span.line, w.span.col) == (1, 1)
    assert robot.joints["a_fixed"].type == "fixed"  # a ball joint: fixed at its reference
    # a spring, as the SDF reader keeps one; springref in degrees, MJCF's default unit
    assert robot.joints["k"].annotations == {"spring_stiffness": 2.0, "spring_reference": np.deg2rad(0.1)}


def test_connect_and_weld_become_loop_closures(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "l.xml", """
        <mujoco model="l">
          <worldbody>
            <body name="a"><joint name="ja" axis="0 1 0"/>
              <geom type="capsule" size="0.02" fromto="0 0 0 1 0 0"/></body>
            <body name="b" pos="2 0 0"><joint name="jb" axis="0 1 0"/>
              <geom type="capsule" size="0.02" fromto="0 0 0 -1 0 0"/></body>
          </worldbody>
          <equality><connect name="c" body1="a" body2="b" anchor="1 0 0"/>
            <weld name="w" body1="a" body2="b"/></equality>
        </mujoco>"""), diags)
    c, w = robot.cut_joints["c"], robot.cut_joints["w"]
    assert (c.type, c.parent, c.child, w.type) == ("ball", "a", "b", "fixed")
    assert c.origin.xyz == (2.0, 0.0, 0.0)
    assert c.annotations["joint_origin"]["xyz"] == [-1.0, 0.0, 0.0]


def test_a_linear_joint_equality_is_a_mimic(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "m.xml", """
        <mujoco model="m">
          <compiler angle="radian"/>
          <worldbody><body name="a"><joint name="ja" axis="0 1 0"/><geom type="sphere" size="0.1"/>
            <body name="b" pos="1 0 0"><joint name="jb" axis="0 1 0" ref="0.2"/>
              <geom type="sphere" size="0.1"/>
              <body name="c" pos="1 0 0"><joint name="jc" axis="0 1 0"/><geom type="sphere" size="0.1"/>
          </body></body></body></worldbody>
          <equality><joint joint1="jb" joint2="ja" polycoef="0.5 -2 0 0 0"/>
            <joint joint1="jc" joint2="ja" polycoef="0 1 0.3 0 0"/></equality>
        </mujoco>"""), diags)
    mimic = robot.joints["jb"].mimic  # q_jb = 0.5 - 2 q_ja, in the IR's zero at jb's ref
    assert (mimic.joint, mimic.multiplier, mimic.offset) == ("ja", -2.0, pytest.approx(0.3, abs=1e-15))
    assert robot.joints["jc"].mimic is None  # a quadratic term: no mimic
    assert diags.take("W0440", Severity.WARNING).message.endswith(
        "holds what mpc's robot model cannot: equality other than a connect or weld of bodies ×1; left out")


def test_mujoco_errors_point_at_file_line_and_column(tmp_path: Path, diags: Diags) -> None:
    path = write(tmp_path / "bad.xml", """
        <mujoco>
          <worldbody>
            <body name="a">
              <joint type="hinge" rnge="1 2"/>
            </body>
          </worldbody>
        </mujoco>""")
    assert _read(path, diags) is None
    e = diags.take_error("E0440")
    assert e.message == f"MuJoCo refuses '{path}': Schema violation: unrecognized attribute: 'rnge'"
    assert (e.span.file, e.span.line, e.span.col) == (str(path), 4, 33)  # at the value MuJoCo quotes


def test_malformed_xml_and_wrong_root(tmp_path: Path, diags: Diags) -> None:
    assert _read(write(tmp_path / "m.xml", "<mujoco><worldbody></mujoco>"), diags) is None
    assert diags.take_error("E0401").span.line == 1
    path = write(tmp_path / "n.xml", "<sdf version='1.9'/>")
    assert _read(path, diags) is None
    assert diags.take_error("E0402").message == (
        f"'{path}' is not an MJCF: its root element is <sdf>, not <mujoco>")


def test_a_urdf_named_xml_is_read_as_urdf(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "r.xml", "<robot name='r'><link name='a'/></robot>"), diags)
    assert robot is not None and list(robot.links) == ["a"]


def test_an_include_or_mesh_outside_the_project_is_refused(tmp_path: Path, diags: Diags) -> None:
    outside = tmp_path / "elsewhere"
    write(outside / "part.xml", "<mujoco><body name='x'/></mujoco>")
    trimesh.creation.box((1, 1, 1)).export(outside / "m.stl")
    project = tmp_path / "project"
    write(project / "robot.yml", "model: {}\n")
    path = write(project / "r.xml", f"""
        <mujoco><worldbody><body name="a"><geom type="sphere" size="1"/>
          <include file="{outside / 'part.xml'}"/></body></worldbody></mujoco>""")
    from mpc.core.packages import PackageResolver

    resolver = PackageResolver()
    resolver.add_project(project)
    assert mjcf_reader.read(path, diags, resolver) is None
    e = diags.take_error("E0650")
    assert e.message.startswith(f"<include> '{outside / 'part.xml'}' is not read: ")
    assert (e.span.line, e.span.col) == (2, 18)
    path = write(project / "s.xml", f"""
        <mujoco><asset><mesh name="m" file="{outside / 'm.stl'}"/></asset>
          <worldbody><body name="a"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>""")
    assert mjcf_reader.read(path, diags, resolver) is None
    assert diags.take_error("E0650").message.startswith(
        f"mesh '{outside / 'm.stl'}' of <mesh> 'm' is not read: ")


def test_mujocos_warnings_are_diagnostics_not_a_log_file(tmp_path: Path, diags: Diags,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    path = write(tmp_path / "t.xml", """
        <mujoco><compiler settotalmass="5"/>
          <worldbody><body name="a"><joint name="j"/><geom type="sphere" size="0.1"/></body></worldbody>
        </mujoco>""")
    robot = _read(path, diags)
    w = diags.take("W0441", Severity.WARNING)
    assert w.message == (f"MuJoCo warns about '{path}': compiler attribute 'settotalmass' is deprecated and "
                         "will be removed in a future release: scale the masses and densities in the model, "
                         "or call mj_setTotalmass and mj_setConst on the compiled model")
    assert robot is not None and robot.links["a"].inertial.mass == pytest.approx(5.0, abs=1e-12)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_included_files_and_meshes_are_in_the_builds_fingerprint(tmp_path: Path, diags: Diags) -> None:
    """`mpc run` fingerprints what a build reads (core/reads.py): MuJoCo's own reads, in C,
    would not be seen; the reader reads every file itself and hands it to MuJoCo."""
    from mpc.core.reads import ReadRecorder, recording

    (tmp_path / "meshes").mkdir()
    trimesh.creation.box((0.1, 0.1, 0.1)).export(tmp_path / "meshes" / "m.stl")
    write(tmp_path / "parts" / "leg.xml", """
        <mujoco><body name="leg"><joint name="knee"/><geom type="mesh" mesh="m"/></body></mujoco>""")
    path = write(tmp_path / "r.xml", """
        <mujoco model="r"><compiler meshdir="meshes"/><asset><mesh name="m" file="m.stl"/></asset>
          <worldbody><body name="hip"><geom type="sphere" size="0.1"/>
            <include file="parts/leg.xml"/></body></worldbody>
        </mujoco>""")
    with recording(ReadRecorder()) as recorder:
        assert _read(path, diags) is not None
    assert {tmp_path / "r.xml", tmp_path / "parts" / "leg.xml", tmp_path / "meshes" / "m.stl"} <= set(
        recorder.inputs())


def test_a_msh_mesh_becomes_an_stl_in_the_cache(tmp_path: Path, diags: Diags,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    box = trimesh.creation.box((0.1, 0.2, 0.3))
    vertices, faces = box.vertices.astype("<f4"), box.faces.astype("<i4")
    header = np.array([len(vertices), 0, 0, len(faces)], dtype="<i4")
    (tmp_path / "box.msh").write_bytes(header.tobytes() + vertices.tobytes() + faces.tobytes())
    path = write(tmp_path / "r.xml", """
        <mujoco model="r"><asset><mesh name="b" file="box.msh"/></asset>
          <worldbody><body name="a"><joint name="j"/><geom type="mesh" mesh="b" pos="0.1 0 0"/></body>
          </worldbody></mujoco>""")
    robot = _read(path, diags)
    mesh = robot.links["a"].visuals[0].geometry
    assert mesh.source.uri == "box.stl" and mesh.source.path.parent == tmp_path / "cache" / "msh"
    stl = trimesh.load(mesh.source.path)
    assert np.allclose(np.sort(stl.vertices, axis=0), np.sort(box.vertices, axis=0), atol=1e-7)
    assert stl.volume == pytest.approx(0.1 * 0.2 * 0.3, rel=1e-6)
    (tmp_path / "bad.msh").write_bytes(header.tobytes())
    bad = write(tmp_path / "bad.xml", """
        <mujoco><asset><mesh name="b" file="bad.msh"/></asset>
          <worldbody><body name="a"><geom type="mesh" mesh="b"/></body></worldbody></mujoco>""")
    assert _read(bad, diags) is None
    e = diags.take_error("E0440")
    assert e.message == (f"MuJoCo refuses '{bad}': mesh file '{tmp_path / 'bad.msh'}' is not a .msh file "
                         "(its sizes do not match its header)")
    assert (e.span.line, e.span.col) == (1, 16)  # the <mesh>


def test_links_and_joints_know_where_they_are_written(tmp_path: Path, diags: Diags) -> None:
    """The language server's hover and go-to-definition show a name's element."""
    write(tmp_path / "parts" / "leg.xml", """
        <mujoco><body name="leg"><joint name="knee"/><geom type="sphere" size="0.1"/></body></mujoco>""")
    path = write(tmp_path / "r.xml", """
        <mujoco model="r">
          <worldbody><body name="hip"><geom type="sphere" size="0.1"/>
            <include file="parts/leg.xml"/></body></worldbody>
        </mujoco>""")
    robot = _read(path, diags)
    hip, leg, knee = robot.links["hip"].span, robot.links["leg"].span, robot.joints["knee"].span
    assert (hip.file, hip.line, hip.col) == (str(path), 2, 14)
    assert (leg.file, leg.line, leg.col) == (str(tmp_path / "parts" / "leg.xml"), 1, 9)
    assert (knee.file, knee.line, knee.col) == (str(tmp_path / "parts" / "leg.xml"), 1, 26)


def test_a_texture_outside_the_project_is_refused(tmp_path: Path, diags: Diags) -> None:
    """MuJoCo's compiler reads textures; mpc hands them to it, under the read rule."""
    from mpc.core.packages import PackageResolver

    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "t.png").write_bytes(b"\x89PNG")
    project = tmp_path / "project"
    write(project / "robot.yml", "model: {}\n")
    resolver = PackageResolver()
    resolver.add_project(project)
    path = write(project / "r.xml", f"""
        <mujoco><asset><texture name="t" type="2d" file="{outside / 't.png'}"/></asset>
          <worldbody><body name="a"><joint name="j"/><geom type="sphere" size="1"/></body></worldbody>
        </mujoco>""")
    assert mjcf_reader.read(path, diags, resolver) is None
    e = diags.take_error("E0650")
    assert e.message.startswith(f"file '{outside / 't.png'}' of <texture> 't' is not read: ")
    assert (e.span.line, e.span.col) == (1, 16)


def test_an_error_in_an_included_file_points_into_it(tmp_path: Path, diags: Diags) -> None:
    leg = write(tmp_path / "leg.xml", """
        <mujoco>
          <body name="leg">
            <joint name="knee" rnge="1"/>
          </body>
        </mujoco>""")
    path = write(tmp_path / "r.xml", """
        <mujoco>
          <worldbody><body name="hip"><include file="leg.xml"/></body></worldbody>
        </mujoco>""")
    assert _read(path, diags) is None
    e = diags.take_error("E0440")
    assert e.message == f"MuJoCo refuses '{path}': Schema violation: unrecognized attribute: 'rnge'"
    assert (e.span.file, e.span.line, e.span.col) == (str(leg), 3, 30)  # at rnge's value


def test_a_number_that_is_not_finite_is_refused(tmp_path: Path, diags: Diags) -> None:
    path = write(tmp_path / "n.xml", """
        <mujoco><worldbody><body name="a" pos="nan 0 0"><joint/><geom size=".1"/></body></worldbody>
        </mujoco>""")
    assert _read(path, diags) is None
    assert diags.take("W0441", Severity.WARNING).message == (
        f"MuJoCo warns about '{path}': XML contains a 'NaN'. Please check it carefully.")
    assert diags.take_error("E0480").message == (
        f"'{path}' compiles to a number that is not finite (a body's position); no output may hold one")


def test_the_names_mpc_makes_take_none_the_file_gives(tmp_path: Path, diags: Diags) -> None:
    robot = _read(write(tmp_path / "c.xml", """
        <mujoco><worldbody>
          <body name="a"><joint name="b_fixed"/><geom size=".1"/><site name="a"/>
            <body name="b"><geom size=".1"/></body></body>
          <body><joint/><geom size=".1"/></body>
          <body name="body3"/>
        </worldbody></mujoco>"""), diags)
    assert list(robot.links) == ["world", "a", "b", "body3_2", "body3", "a_site"]
    assert {n: (j.parent, j.child) for n, j in robot.joints.items()} == {
        "b_fixed": ("world", "a"), "b_fixed_2": ("a", "b"), "body3_2_joint1": ("world", "body3_2"),
        "body3_fixed": ("world", "body3"), "a_site_fixed": ("a", "a_site")}


def test_an_attached_model_is_read_like_an_include(tmp_path: Path, diags: Diags) -> None:
    """`<attach>` takes a `<model>` asset's file: read by mpc (the read rule, the fingerprint)
    and handed to MuJoCo, which attaches it with its prefix."""
    from mpc.core.reads import ReadRecorder, recording

    write(tmp_path / "sub" / "grip.xml", """
        <mujoco model="g"><worldbody><body name="g"><joint name="gj" range="-1 1"/><geom size=".1"/></body>
        </worldbody></mujoco>""")
    path = write(tmp_path / "r.xml", """
        <mujoco><asset><model name="grip" file="sub/grip.xml"/></asset>
          <worldbody><body name="a"><joint name="j"/><geom size=".1"/>
            <attach model="grip" body="g" prefix="l_"/></body></worldbody></mujoco>""")
    with recording(ReadRecorder()) as recorder:
        robot = _read(path, diags)
    assert robot.joints["l_gj"].parent == "a" and robot.joints["l_gj"].limit.upper == pytest.approx(
        np.pi / 180)
    assert tmp_path / "sub" / "grip.xml" in recorder.inputs()
    missing = write(tmp_path / "m.xml", """
        <mujoco><asset><model name="grip" file="sub/nope.xml"/></asset><worldbody/></mujoco>""")
    assert _read(missing, diags) is None
    assert diags.take_error("E0601").message == (
        "<model> 'sub/nope.xml' does not exist")
