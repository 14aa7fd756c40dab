"""The SDF backend: every example-robot-data URDF written as SDF is valid for sdformat 12
(`ign sdf -k`) and reads back as the same robot; canonical bytes; the axis and pose
conventions checked against sdformat's own URDF conversion; cassie's SDFs; diagnostics."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from mpc.backends import sdf, sdf_reader, urdf
from mpc.core.diagnostics import Severity, Sink
from mpc.core.span import Span
from mpc.ir import transforms as tf
from mpc.ir.geometry import Mesh
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.program import SdfExport
from mpc.ir.robot import Robot
from tests.backends.test_urdf_real_models import GOOD
from tests.conftest import ERD, Diags, write

IGN = shutil.which("ign")
needs_ign = pytest.mark.skipif(IGN is None, reason="ign (ignition-tools + libsdformat12) is not installed")
W = Severity.WARNING
CASSIE = ERD / "cassie_description/robots"

# Models whose own inertias sdformat rejects ("A link named X has invalid inertia"): the
# principal moments violate the triangle inequality (Ixx + Iyy ≥ Izz) or are negative. The
# SDF export refuses them (E0504) unless `correct_inertials` is set.
BAD_INERTIA: dict[str, tuple[set[str], str]] = {
    "alex_description/urdf/alex_psyonic_hands.urdf": (
        {"LeftPsyonicAbilityBaseLink", "Left_thumb_base", "RightPsyonicAbilityBaseLink", "Right_thumb_base"},
        "principal moments 2.7e-4, 1.0e-3, 1.4e-3: triangle inequality violated"),
    "allegro_hand_description/urdf/allegro_left_hand.urdf": (
        {"link_3.0", "link_7.0", "link_11.0", "link_15.0"}, "fingertips violate the triangle inequality"),
    "allegro_hand_description/urdf/allegro_right_hand.urdf": (
        {"link_3.0", "link_7.0", "link_11.0", "link_15.0"}, "fingertips violate the triangle inequality"),
    "anymal_b_simple_description/robots/anymal-kinova.urdf": (
        {"base"}, "1 mg placeholder with inertia diag(0, 0, 3e-6): triangle inequality violated"),
    "anymal_b_simple_description/robots/anymal.urdf": ({"base"}, "the same placeholder base"),
    "anymal_c_simple_description/urdf/anymal.urdf": (
        {"depth_camera_front_camera", "depth_camera_rear_camera", "depth_camera_left_camera",
         "depth_camera_right_camera", "hatch"}, "camera and hatch inertias violate the triangle inequality"),
    "b1_description/urdf/b1-z1.urdf": ({"base"}, "1 mg placeholder base, inertia diag(0, 0, 3e-6)"),
    "b1_description/urdf/b1.urdf": ({"base"}, "1 mg placeholder base, inertia diag(0, 0, 3e-6)"),
    "go1_description/urdf/go1.urdf": ({"base"}, "1 mg placeholder base, inertia diag(0, 0, 3e-6)"),
    "hyq_description/robots/hyq_no_sensors.urdf": (
        {"base_link", "lf_foot", "lh_foot", "rf_foot", "rh_foot"}, "1 mg placeholders, diag(0, 0, 3e-6)"),
    "icub_description/robots/icub.urdf": (
        {"l_ankle_2", "r_hip_2", "r_upper_leg", "r_lower_leg", "r_ankle_1", "r_ankle_2", "head"},
        "inertias of about 1e-20 with negative principal moments"),
    "icub_description/robots/icub_reduced.urdf": (
        {"l_ankle_2", "r_hip_2", "r_upper_leg", "r_lower_leg", "r_ankle_1", "r_ankle_2", "head"},
        "inertias of about 1e-20 with negative principal moments"),
    "pr2_description/urdf/pr2.urdf": (
        {"sensor_mount_link", "double_stereo_link"}, "inertia diag(1e-3, 1e-3, 1e-2): triangle inequality"),
    "romeo_description/urdf/romeo_small.urdf": (
        {"RShoulderYawLink", "RElbowYawLink"}, "right-arm inertias violate the triangle inequality"),
    "tiago_description/robots/tiago.urdf": (
        {"base_antenna_left_link", "base_antenna_right_link"}, "antenna inertias are not positive definite"),
    "tiago_description/robots/tiago_dual.urdf": (
        {"base_antenna_left_link", "base_antenna_right_link"}, "antenna inertias are not positive definite"),
    "tiago_description/robots/tiago_no_hand.urdf": (
        {"base_antenna_left_link", "base_antenna_right_link"}, "antenna inertias are not positive definite"),
}


def _uri(mesh: Mesh) -> str:
    return mesh.source.uri


def _export(version: str = "1.9", mesh_format: str = "input_type") -> SdfExport:
    return SdfExport(mesh_format=mesh_format, span=Span("model.yml", 3, 5), version=version)  # type: ignore[arg-type]


def _check(path: Path) -> subprocess.Popen[str]:
    """`ign sdf -k path`, started (about 0.3 s each, so the caller works meanwhile)."""
    return subprocess.Popen([IGN or "ign", "sdf", "-k", str(path)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)


def _complaints(check: subprocess.Popen[str]) -> list[str]:
    out, _ = check.communicate(timeout=60)
    # ignition-tools prints this on every run when its optional backtrace library is missing.
    return [ln for ln in out.splitlines() if ln.strip() and "libignition-tools-backward" not in ln]


def _read_urdf(path: Path) -> Robot:
    sink = Sink()
    robot = urdf.read(path, sink)
    assert robot is not None and not sink.has_errors(), [d.message for d in sink.diagnostics]
    return robot


def _take_expected_warnings(robot: Robot, diags: Diags) -> None:
    links, joints = sdf.sdf_names(robot)
    if sdf.left_out(robot):
        assert diags.take("W0500", W).message.startswith("the SDF leaves out")
    if links != {n: n for n in links} or joints != {n: n for n in joints}:
        assert diags.take("W0501", W).message.startswith("the SDF renames")


def _mass(robot: Robot) -> float:
    return sum(lk.inertial.mass for lk in robot.links.values() if lk.inertial is not None)


@needs_ign
@pytest.mark.parametrize("model", GOOD)
def test_every_model_is_valid_sdf_and_reads_back(model: str, tmp_path: Path, diags: Diags) -> None:
    """Every model is written as SDF that `ign sdf -k` accepts. A model whose inertias
    SDFormat refuses is not written (E0504 names exactly the links `ign sdf -k` names in its
    text written anyway), and is written valid with `correct_inertials`."""
    robot = _read_urdf(ERD / model)
    if model in BAD_INERTIA:
        robot = _refused_then_corrected(model, robot, tmp_path, diags)
    sdf.emit(robot, _export(), tmp_path, diags)
    _take_expected_warnings(robot, diags)
    path = tmp_path / "sdf" / f"{robot.name}.sdf"
    check = _check(path)

    back = sdf_reader.read(path, diags)
    assert back is not None
    links, joints = sdf.sdf_names(robot)
    assert set(back.links) == set(links.values())
    assert set(back.joints) == {joints[j.name] for j in robot.joints.values()
                                if j.type not in ("floating", "planar")}
    assert abs(_mass(back) - _mass(robot)) <= 1e-9
    for name in robot.links:
        np.testing.assert_allclose(link_in_root(back, links[name]), link_in_root(robot, name),
                                   atol=1e-9, rtol=0, err_msg=name)
    for mesh in etree.parse(str(path)).getroot().iter("uri"):
        assert (path.parent / mesh.text).is_file()
    config = etree.parse(str(tmp_path / "sdf" / "model.config")).getroot()
    assert config.findtext("sdf") == path.name and config.findtext("name") == robot.name
    assert _complaints(check) == ["Valid."]


def _refused_then_corrected(model: str, robot: Robot, tmp_path: Path, diags: Diags) -> Robot:
    """The export refuses `robot` (E0504, one per link SDFormat refuses, as `ign sdf -k`
    names them in the text written without the check); the robot `correct_inertials` makes."""
    from mpc.ir.physical import correct_inertials

    unchecked = tmp_path / "unchecked.sdf"
    unchecked.write_text(sdf.to_string(robot, _uri))
    check = _check(unchecked)
    sdf.emit(robot, _export(), tmp_path / "refused", diags)
    _take_expected_warnings(robot, diags)
    refused = set()
    while any(d.code == "E0504" for d in diags.diagnostics):
        error = diags.take("E0504")
        assert error.hint == ("set `correct_inertials: true` on the export to make it physical, "
                              "or fix its inertial")
        refused.add(error.message.split("'")[1])
    assert refused == BAD_INERTIA[model][0]
    assert not (tmp_path / "refused" / "sdf").exists()
    complaints = _complaints(check)
    named = {m.group(1) for ln in complaints
             if (m := re.search(r"A link named (\S+) has invalid inertia", ln))}
    assert named == refused, complaints
    assert all("Error Code 18" in ln for ln in complaints), complaints
    corrected, changed = correct_inertials(robot, exact=True)
    assert refused <= set(changed)
    return corrected


def test_writing_twice_gives_identical_bytes(tmp_path: Path, diags: Diags) -> None:
    robot = _read_urdf(ERD / "talos_data/robots/talos_full_v2.urdf")
    for out in ("a", "b"):
        sdf.emit(robot, _export(), tmp_path / out, diags)
        _take_expected_warnings(robot, diags)
    files = [{str(p.relative_to(tmp_path / out)): p.read_bytes() for p in sorted((tmp_path / out).rglob("*"))
              if p.is_file()} for out in ("a", "b")]
    assert files[0] == files[1]
    assert len(files[0]) == 2 + len(list((tmp_path / "a" / "meshes").rglob("*.*")))
    text = files[0]["sdf/talos.sdf"].decode()
    assert '-->\n<sdf version="1.9">\n  <model name="talos">\n' in text
    assert '<link name="base_link">\n      <pose>0 0 0 0 0 0</pose>\n' in text
    # A robot read again gives the same bytes; the versions differ only in their header.
    again = sdf.to_string(_read_urdf(ERD / "talos_data/robots/talos_full_v2.urdf"), _uri)
    assert sdf.to_string(robot, _uri) == again
    assert sdf.to_string(robot, _uri, "1.6") == again.replace('<sdf version="1.9">', '<sdf version="1.6">')


def test_a_shape_named_by_spaces_only_gets_a_name_sdformat_reads(tmp_path: Path, diags: Diags) -> None:
    """sdformat trims a name, and refuses a shape whose name is then empty ("Empty string used
    when setting a required parameter"): a visual named " " (a tab in an SDF input, read by XML
    as a space; found by the fuzz run of seed 1132) was written so. It gets the name an unnamed
    shape gets, and a name with spaces around is written as sdformat reads it."""
    write(tmp_path / "in/spaced.urdf", """
        <robot name="spaced"><link name="base">
          <visual name=" "><geometry><box size="1 1 1"/></geometry></visual>
          <collision name=" hull "><geometry><box size="1 1 1"/></geometry></collision>
        </link></robot>""")
    robot = _read_urdf(tmp_path / "in/spaced.urdf")
    sdf.emit(robot, _export(), tmp_path / "out", diags)
    _take_expected_warnings(robot, diags)
    written = tmp_path / "out/sdf/spaced.sdf"
    check = _check(written)
    text = written.read_text()
    assert '<visual name="base_visual">' in text and '<collision name="hull">' in text
    assert _complaints(check) == ["Valid."]


UNIT_INERTIA = '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
ROTATED = """\
<robot name="rotated">
  <link name="a"><inertial><mass value="1"/>{I}</inertial></link>
  <joint name="j1" type="revolute"><origin xyz="0.1 0.2 0.3" rpy="0.4 0.5 0.6"/><parent link="a"/>
    <child link="b"/><axis xyz="0 0.6 0.8"/><limit lower="-1" upper="2" effort="3" velocity="4"/>
    <dynamics damping="0.5" friction="0.25"/></joint>
  <link name="b"><inertial><origin xyz="0.01 0 0" rpy="0 0 1"/><mass value="2"/>
    {I}</inertial>
    <visual><origin xyz="0 0 0.2" rpy="0.1 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual></link>
  <joint name="j2" type="continuous"><origin xyz="1 0 0" rpy="1.2 1.5707963 -0.3"/><parent link="b"/>
    <child link="c"/><axis xyz="1 0 0"/></joint>
  <link name="c"><inertial><mass value="1"/>{I}</inertial>
    <collision><geometry><cylinder radius="0.1" length="0.5"/></geometry></collision></link>
  <joint name="j3" type="prismatic"><origin xyz="0 1 0" rpy="0 0.3 0"/><parent link="c"/><child link="d"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.5" effort="3" velocity="4"/></joint>
  <link name="d"><inertial><mass value="1"/>{I}</inertial>
    <visual><geometry><sphere radius="0.05"/></geometry></visual></link>
</robot>
""".replace("{I}", UNIT_INERTIA)


def _axes_in_root(robot: Robot) -> dict[str, np.ndarray]:
    return {j.name: link_in_root(robot, j.child)[:3, :3] @ np.array(j.axis or (1.0, 0.0, 0.0))
            for j in robot.joints.values() if j.type != "fixed"}


def _assert_same_kinematics(a: Robot, b: Robot, tol: float) -> None:
    assert set(a.links) == set(b.links) and set(a.joints) == set(b.joints)
    for name in a.links:
        np.testing.assert_allclose(link_in_root(b, name), link_in_root(a, name), atol=tol, rtol=0)
    axes_a, axes_b = _axes_in_root(a), _axes_in_root(b)
    for name, joint in a.joints.items():
        assert b.joints[name].type == joint.type
        assert b.joints[name].limit == joint.limit and b.joints[name].dynamics == joint.dynamics
        if name in axes_a:
            np.testing.assert_allclose(axes_b[name], axes_a[name], atol=tol, rtol=0)


@needs_ign
def test_axis_in_joint_frame_matches_sdformats_own_urdf_conversion(tmp_path: Path, diags: Diags) -> None:
    """The writer puts each joint frame on its child link and writes the axis without
    expressed_in (in the joint frame), as the IR holds it. sdformat's URDF parser does
    the same with poses relative to joints: both read back as the URDF's kinematics."""
    source = write(tmp_path / "rotated.urdf", ROTATED)
    robot = _read_urdf(source)
    ours = write(tmp_path / "ours.sdf", sdf.to_string(robot, _uri))
    assert "expressed_in" not in ours.read_text() and "<xyz>0 0.6 0.8</xyz>" in ours.read_text()
    theirs = subprocess.run([IGN or "ign", "sdf", "-p", str(source)], capture_output=True, text=True,
                            check=True)
    assert "relative_to='j1'" in theirs.stdout  # their link poses hang from joint frames
    # sdformat turns j2's rpy (1.2, 1.5707963, -0.3), near gimbal lock, into (1.5,
    # 1.570796305721472, 0): its quaternion → Euler conversion moves the frame by 7e-9.
    for text, tol in ((ours.read_text(), 1e-12), (theirs.stdout, 1e-8)):
        back = sdf_reader.read(write(tmp_path / "back.sdf", text), diags)
        assert back is not None
        _assert_same_kinematics(robot, back, tol)
    assert back.links["b"].visuals[0].inline_material.rgba == (1, 0, 0, 1)
    for version in ("1.6", "1.7", "1.9"):  # the same text, which all three accept
        path = write(tmp_path / f"ours-{version}.sdf", sdf.to_string(robot, str, version))
        assert _complaints(_check(path)) == ["Valid."], version


MOVED_JOINT = """\
<sdf version="1.9">
  <model name="moved">
    <link name="base"><pose>0 0 1 0 0 0</pose></link>
    <link name="arm">
      <pose degrees="true">1 0 1 0 0 90</pose>
      <sensor name="imu" type="imu"><always_on>1</always_on></sensor>
      <visual name="tip"><pose relative_to="__model__">2 0 1 0 0 0</pose>
        <geometry><sphere><radius>0.1</radius></sphere></geometry></visual>
    </link>
    <frame name="hinge" attached_to="base"><pose relative_to="base">0.5 0 0 0 0 0</pose></frame>
    <joint name="elbow" type="revolute">
      <pose relative_to="hinge">0 0 0 0 0 0</pose>
      <parent>base</parent><child>arm</child>
      <axis><xyz expressed_in="__model__">0 0 1</xyz><limit><lower>-1</lower><upper>1</upper>
        <effort>5</effort><velocity>2</velocity></limit></axis>
    </joint>
  </model>
</sdf>
"""


def test_joint_away_from_its_child_moves_the_child_frame_not_the_motion(tmp_path: Path, diags: Diags) -> None:
    """SDF's joint at `hinge` (0.5 m from base), axis in the model frame: the IR's child frame
    moves to the joint, keeps its orientation, and every point moves as in SDF."""
    robot = sdf_reader.read(write(tmp_path / "moved.sdf", MOVED_JOINT), diags)
    assert robot is not None and robot.root == "base"
    root_pose = {"xyz": [0.0, 0.0, 1.0], "rpy": [0.0, 0.0, 0.0]}
    assert robot.annotations == {"sdf": {"root_pose_in_model": root_pose}}
    assert [(f.tag, f.names("link")) for f in robot.fragments] == [("gazebo", {"arm"})]
    assert robot.fragments[0].xml.startswith('<gazebo reference="arm">\n  <sensor name="imu" type="imu">')
    joint = robot.joints["elbow"]
    np.testing.assert_allclose(joint.origin.xyz, (0.5, 0, 0), atol=1e-15)
    np.testing.assert_allclose(joint.axis, (0, 0, 1), atol=1e-15)
    q = 0.3
    X_RT = link_in_root(robot, "arm") @ tf.pose_to_matrix((0, 0, 0), (0, 0, q)) @ pose_matrix(
        robot.links["arm"].visuals[0].origin)
    # In SDF: the tip (2, 0, 1) in the model turns by q about z through the hinge (0.5, 0, 1).
    tip = np.array([0.5 + 1.5 * math.cos(q), 1.5 * math.sin(q), 0.0])
    np.testing.assert_allclose(X_RT[:3, 3], tip, atol=1e-12)


def test_cassie_v2_reads_with_its_loops_as_cut_joints(diags: Diags) -> None:
    robot = sdf_reader.read(CASSIE / "cassie_v2.sdf", diags)
    assert robot is not None and robot.root == "pelvis"
    assert len(robot.links) == 23 and len(robot.joints) == 22
    assert abs(_mass(robot) - 32.94) < 1e-9  # Agility's Cassie weighs about 31 kg plus its feet
    cuts = {n: (c.type, c.parent, c.child) for n, c in robot.cut_joints.items()}
    assert cuts == {
        "left-pitch-rod-joint": ("ball", "left-achilles-rod", "left-hip-pitch"),
        "right-pitch-rod-joint": ("ball", "right-achilles-rod", "right-hip-pitch"),
        "left-plantar-foot-joint": ("ball", "left-plantar-rod", "left-foot"),
        "right-plantar-foot-joint": ("ball", "right-plantar-rod", "right-foot")}
    assert {j.type for j in robot.joints.values()} == {"revolute", "continuous"}
    meshes = [v.geometry for lk in robot.links.values() for v in lk.visuals]
    assert meshes and all(m.source.path is not None and m.source.path.is_file() for m in meshes)
    # The model stands with its pelvis 1.01 m up, its feet on the ground (z = 0).
    assert robot.annotations["sdf"]["root_pose_in_model"]["xyz"] == [0.0, 0.0, 1.01]
    assert abs(link_in_root(robot, "left-foot")[2, 3] + 1.01) < 0.01
    assert [f.tag for f in robot.fragments] == ["gazebo"] and "CassiePlugin" in robot.fragments[0].xml


@needs_ign
def test_cassie_v2_writes_back_as_valid_sdf_without_its_loops(tmp_path: Path, diags: Diags) -> None:
    robot = sdf_reader.read(CASSIE / "cassie_v2.sdf", diags)
    assert robot is not None
    path = write(tmp_path / "cassie.sdf", sdf.to_string(robot, lambda m: str(m.source.path), sink=diags))
    message = diags.take("W0500", W).message
    assert "4 loop-closure joints" in message and "1 <gazebo> fragment" in message
    assert _complaints(_check(path)) == ["Valid."]


def test_cassie_with_a_ball_joint_in_its_tree_is_located(diags: Diags) -> None:
    assert sdf_reader.read(CASSIE / "cassie.sdf", diags) is None
    lines = (CASSIE / "cassie.sdf").read_text().splitlines()
    for side, line in (("left", 360), ("right", 1131)):
        d = diags.take_error("E0202")
        assert d.message.startswith(f"joint '{side}-pitch-rod-joint' of type 'ball' is needed")
        assert d.span.line == line and lines[line - 1][d.span.col - 1:d.span.end_col - 1] == "ball"


@pytest.mark.parametrize(("text", "code", "where", "words"), [
    ("<sdf version='1.9'><model name='m'>\n  <link name='a'>\n</model></sdf>", "E0401", (3, 9), "mismatch"),
    ("<robot name='r'/>", "E0402", (1, 1), "not an SDF"),
    ("<sdf version='1.4'><model name='m'/></sdf>", "E0202", (1, 15), "version '1.4'"),
    ("<sdf version='1.9'>\n<model name='m'>\n  <link name='a'/>\n  <joint name='j' type='fixed'>\n"
     "    <parent>nope</parent><child>a</child></joint></model></sdf>", "E0411", (5, 5), "unknown parent"),
    ("<sdf version='1.7'><model name='m'>\n<link name='a'><pose>1 2 x 0 0 0</pose></link></model></sdf>",
     "E0404", (2, 16), "6 numbers"),
    ("<sdf version='1.9'><model name='m'>\n<link name='a'><visual name='v'><geometry>\n"
     "  <capsule><radius>1</radius><length>2</length></capsule></geometry></visual></link></model></sdf>",
     "E0202", (3, 3), "geometry <capsule>"),
    ("<sdf version='1.9'><model name='m'>\n<link name='a'/>\n<joint name='a' type='fixed'/></model></sdf>",
     "E0410", (3, 14), "duplicate name 'a'"),
])
def test_broken_sdf_gives_a_located_diagnostic(tmp_path: Path, diags: Diags, text: str, code: str,
                                               where: tuple[int, int], words: str) -> None:
    path = write(tmp_path / "broken.sdf", text)
    assert sdf_reader.read(path, diags) is None
    d = diags.take_error(code)
    assert (d.span.file, d.span.line, d.span.col) == (str(path), *where) and words in d.message, d


ODD = """\
<robot name="odd">
  <link name="world"/>
  <joint name="float" type="floating"><parent link="world"/><child link="base"/></joint>
  <link name="base"><inertial><mass value="3"/>{I}</inertial></link>
  <joint name="slide" type="planar"><parent link="base"/><child link="puck"/></joint>
  <link name="puck"/>
  <joint name="a" type="revolute"><parent link="base"/><child link="finger"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <link name="finger"/>
  <joint name="b" type="revolute"><origin xyz="0 0 1"/><parent link="base"/><child link="finger2"/>
    <mimic joint="a" multiplier="-1"/><limit lower="-1" upper="0" effort="1" velocity="1"/></joint>
  <link name="finger2"/>
  <gazebo><plugin name="p" filename="p.so"/></gazebo>
</robot>
""".replace("{I}", UNIT_INERTIA)


@needs_ign
def test_what_sdf_cannot_hold_is_named_in_one_warning(tmp_path: Path, diags: Diags) -> None:
    robot = _read_urdf(write(tmp_path / "odd.urdf", ODD))
    path = write(tmp_path / "odd.sdf", sdf.to_string(robot, str, sink=diags))
    message = diags.take("W0500", W).message
    assert message == (
        "the SDF leaves out what SDFormat 1.9 cannot hold or mpc does not translate: floating joint "
        "'float' (SDF has none: link 'base' is written free); planar joint 'slide' (SDF has none: "
        "link 'puck' is written free); the mimic of joint 'b'; 1 <gazebo> fragment")
    text = path.read_text()
    assert "world" not in text and "<mass>0</mass>" in text  # massless, not SDF's default 1 kg
    assert _complaints(_check(path)) == ["Valid."]
    assert sdf_reader.read(path, diags) is None  # puck is a second root
    assert "2 root links (base, puck)" in diags.take_error("E0414").message
