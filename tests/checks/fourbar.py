"""A planar four-bar linkage (a parallelogram at q = 0), written as a tree plus one cut joint.

The crank (`crank_joint`) is driven; coupler and rocker follow. Links are 1 m (crank,
rocker) and 2 m (coupler) long, masses 1, 2 and 3 kg, all rotating about y. At crank
angle θ the coupler translates and the rocker turns by θ, so the torque that holds the
crank against gravity is τ = -g sin θ (m_crank/2 + m_coupler + m_rocker/2).
"""

from __future__ import annotations

FOURBAR_URDF = """\
<?xml version="1.0"?>
<robot name="fourbar">
  <link name="base">
    <inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><origin xyz="1 0 -0.05"/><geometry><box size="2.2 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="crank_joint" type="revolute">
    <parent link="base"/><child link="crank"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
  <link name="crank">
    <inertial><origin xyz="0 0 0.5"/><mass value="1"/>
      <inertia ixx="0.084" ixy="0" ixz="0" iyy="0.084" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 0.5"/><geometry><box size="0.05 0.05 1"/></geometry></collision>
  </link>
  <joint name="coupler_joint" type="revolute">
    <origin xyz="0 0 1"/><parent link="crank"/><child link="coupler"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
  <link name="coupler">
    <inertial><origin xyz="1 0 0"/><mass value="2"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.67" iyz="0" izz="0.67"/></inertial>
    <collision><origin xyz="1 0 0"/><geometry><box size="2 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="coupler_tip_joint" type="fixed">
    <origin xyz="2 0 0"/><parent link="coupler"/><child link="coupler_tip"/>
  </joint>
  <link name="coupler_tip"/>
  <joint name="rocker_joint" type="revolute">
    <origin xyz="2 0 0"/><parent link="base"/><child link="rocker"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
  <link name="rocker">
    <inertial><origin xyz="0 0 0.5"/><mass value="3"/>
      <inertia ixx="0.25" ixy="0" ixz="0" iyy="0.25" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 0.5"/><geometry><box size="0.05 0.05 1"/></geometry></collision>
  </link>
  <joint name="rocker_tip_joint" type="fixed">
    <origin xyz="0 0 1"/><parent link="rocker"/><child link="rocker_tip"/>
  </joint>
  <link name="rocker_tip"/>
</robot>
"""

# The definition that closes the loop and drives the crank.
FOURBAR_DEFINITION = """\
model:
  robotname: fourbar
  modelname: fourbar-model
  input_models:
    base:
      basefile: fourbar.urdf
  assemble:
    model: base
  joints:
    loop:
      cut_joint: true
      type: revolute
      parent: coupler_tip
      child: rocker_tip
    crank_joint:
      active: true
  export_config:
    - type: urdf
      mesh_format: input_type
"""
