"""What MJCF and SDF cannot hold (W0500), as tables (backends/holds.py): the phrases, their
order and their counts, byte for byte as the chains of conditions they replaced said them
(recorded from that code on these robots)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from mpc.backends import holds, mjcf, sdf, urdf_reader
from mpc.core.diagnostics import Sink
from mpc.ir.extras import CutJoint, Motor, Sensor, Submechanism
from mpc.ir.robot import Pose, Robot
from tests.conftest import write

RICH_URDF = """\
<?xml version="1.0"?>
<robot name="rich">
  <material name="tex"><color rgba="1 0 0 1"/><texture filename="a.png"/></material>
  <link name="world"><inertial><mass value="2"/>{I}</inertial></link>
  <link name="base" extra="1">
    <inertial><mass value="1"/>{I}<custom/></inertial>
    <visual name="v"><geometry><box size="1 1 1" foo="2"/></geometry><material name="tex"/><note/></visual>
    <collision name="v"><geometry><sphere radius="1"/></geometry></collision>
    <collision name="v"><geometry><sphere radius="0.5"/></geometry></collision>
    <sensorish/>
  </link>
  <link name="a"><inertial><mass value="1"/>{I}</inertial></link>
  <link name="b"><inertial><mass value="1"/>{I}</inertial></link>
  <link name="c"><inertial><mass value="1"/>{I}</inertial></link>
  <link name="d"><inertial><mass value="1"/>{I}</inertial></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="j1" type="revolute" bar="x"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="1" upper="0" effort="1" velocity="2" baz="3"/><calibration rising="0.1"/>
    <safety_controller k_velocity="1"/><dynamics damping="0.1" qux="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="2"/><mimic joint="j1" multiplier="2"/></joint>
  <joint name="fl" type="floating"><parent link="b"/><child link="c"/></joint>
  <joint name="pl" type="planar"><parent link="c"/><child link="d"/><axis xyz="0 0 1"/>
    <mimic joint="j2"/></joint>
  <transmission name="t"><type>x</type></transmission>
  <gazebo reference="a"><mu1>1</mu1></gazebo>
  <gazebo><plugin name="p" filename="x.so"/></gazebo>
</robot>
""".replace("{I}", '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>')


def _rich(tmp_path: Path) -> Robot:
    robot = urdf_reader.read(write(tmp_path / "rich.urdf", RICH_URDF), Sink())
    assert robot is not None
    return robot


def _enriched(robot: Robot) -> Robot:
    """`robot` with what a URDF cannot say: motors, sensors, cut joints, poses, submechanisms,
    annotation categories, an annotated link."""
    links = dict(robot.links)
    links["b"] = dataclasses.replace(links["b"], annotations={"k": 1})
    return dataclasses.replace(
        robot, links=links,
        motors={"m1": Motor(name="m1", joint="j1", settings={"p": 1, "i": 2}),
                "m2": Motor(name="m2", joint="j2")},
        sensors={"imu": Sensor(name="imu", type="IMU", link="a"),
                 "x": Sensor(name="x", type="Weird", link="a"), "f": Sensor(name="f", type="Joint6DOF")},
        cut_joints={"cw": CutJoint(name="cw", type="fixed", parent="a", child="c", origin=Pose()),
                    "cr": CutJoint(name="cr", type="revolute", parent="a", child="d", origin=Pose(),
                                   constraint_axes=(("x", (1.0, 0.0, 0.0)),)),
                    "cp": CutJoint(name="cp", type="prismatic", parent="b", child="d", origin=Pose())},
        poses={"home": {"j1": 0.0}}, submechanisms=(Submechanism(name="s"),),
        submechanisms_file="sub.yml", annotations={"cat": {}, "cat2": {}})


MJCF_RICH = [
    '2 joint velocity limits',
    '1 joint calibration',
    '1 safety controller',
    '1 empty position range (lower ≥ upper)',
    '1 material texture or property beyond colour',
    '3 names of visuals or collisions used twice',
    '2 attributes URDF does not define',
    '1 mimic of or by a joint without one degree of freedom',
    '1 <custom> element',
    '2 <gazebo> elements',
    '1 <note> element',
    '1 <sensorish> element',
    '1 <transmission> element',
    "the mass of the root link 'world' (MuJoCo's world body has none)",
]
SDF_RICH = [
    "floating joint 'fl' (SDF has none: link 'c' is written free)",
    "planar joint 'pl' (SDF has none: link 'd' is written free)",
    "the mimic of joints 'j2', 'pl'",
    '1 joint calibration',
    '1 joint safety controller',
    '1 <transmission> fragment',
    '2 <gazebo> fragments',
    '<custom> in 1 inertial',
    "attribute 'bar' of 1 joint",
    "attribute 'baz' of 1 joint",
    "attribute 'qux' of 1 joint",
    '<sensorish> in 1 link',
    "attribute 'extra' of 1 link",
    '<note> in 1 visual',
    "attribute 'foo' of the geometry in 1 visual",
    '1 material texture',
]
MJCF_ENRICHED = [
    '3 sensors',
    '1 submechanism',
    '2 annotation categories',
    '1 annotated link or joint',
    '2 joint velocity limits',
    '1 joint calibration',
    '1 safety controller',
    '1 empty position range (lower ≥ upper)',
    '1 material texture or property beyond colour',
    '3 names of visuals or collisions used twice',
    '2 attributes URDF does not define',
    '1 mimic of or by a joint without one degree of freedom',
    '1 motor setting',  # m1's i (p is its actuator's kp; poses are keyframes)
    '1 cut joint constraint axis',
    "1 rotational cut joint's axis (without one, a connect is a ball joint)",
    "prismatic cut joint 'cp' (MJCF has no equality for it)",
    '1 <custom> element',
    '2 <gazebo> elements',
    '1 <note> element',
    '1 <sensorish> element',
    '1 <transmission> element',
    "the mass of the root link 'world' (MuJoCo's world body has none)",
    'the submechanisms file',
]
SDF_ENRICHED = [
    "floating joint 'fl' (SDF has none: link 'c' is written free)",
    "planar joint 'pl' (SDF has none: link 'd' is written free)",
    "the mimic of joints 'j2', 'pl'",
    '2 motors',
    '2 sensors SDF has no type for',
    '1 named pose',
    '3 loop-closure joints',
    '1 submechanism',
    '2 annotation categories',
    '1 joint calibration',
    '1 joint safety controller',
    '1 <transmission> fragment',
    '2 <gazebo> fragments',
    '<custom> in 1 inertial',
    "attribute 'bar' of 1 joint",
    "attribute 'baz' of 1 joint",
    "attribute 'qux' of 1 joint",
    'annotations of 1 link',
    '<sensorish> in 1 link',
    "attribute 'extra' of 1 link",
    '<note> in 1 visual',
    "attribute 'foo' of the geometry in 1 visual",
    '1 material texture',
    'the submechanisms file',
]
# With `cut_joints` the SDF holds the loop closures: the same list but for them.
SDF_ENRICHED_WITH_CUT_JOINTS = [phrase for phrase in SDF_ENRICHED if phrase != "3 loop-closure joints"]


def test_mjcf_left_out_says_what_the_chain_of_conditions_said(tmp_path: Path) -> None:
    robot = _rich(tmp_path)
    assert mjcf.left_out(robot) == MJCF_RICH
    assert mjcf.left_out(_enriched(robot)) == MJCF_ENRICHED


def test_sdf_left_out_says_what_the_chain_of_conditions_said(tmp_path: Path) -> None:
    robot = _rich(tmp_path)
    assert sdf.left_out(robot) == sdf.left_out(robot, cut_joints=True) == SDF_RICH
    assert sdf.left_out(_enriched(robot)) == SDF_ENRICHED
    assert sdf.left_out(_enriched(robot), cut_joints=True) == SDF_ENRICHED_WITH_CUT_JOINTS


def test_a_robot_holding_nothing_extra_leaves_nothing_out(tmp_path: Path) -> None:
    robot = urdf_reader.read(write(tmp_path / "plain.urdf", """\
        <robot name="plain"><link name="base"/><link name="arm"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="arm"/></joint></robot>
        """), Sink())
    assert robot is not None
    assert mjcf.left_out(robot) == sdf.left_out(robot) == []


def test_left_out_adds_equal_phrases_in_first_seen_order_and_drops_the_uncounted(tmp_path: Path) -> None:
    robot = _rich(tmp_path)
    table = (holds.count(holds.noun("bolt"), lambda r, o: 0),
             holds.count(holds.Counted("link", "links"), lambda r, o: len(r.links)),
             holds.count(holds.noun("bolt"), lambda r, o: o["bolts"]),
             holds.named(holds.Named("the rest"), lambda r, o: True))
    assert holds.left_out(robot, table, bolts=1) == ["1 bolt", "6 links", "the rest"]
    assert holds.left_out(robot, table, bolts=0) == ["6 links", "the rest"]
