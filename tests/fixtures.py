"""Small models the tests write themselves: a three-link arm with a real STL mesh."""

from __future__ import annotations

import struct
from pathlib import Path

from tests.conftest import write

ARM_URDF = """\
<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial>
      <origin xyz="0 0 0.05"/>
      <mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <visual>
      <geometry><mesh filename="meshes/tetra.stl"/></geometry>
    </visual>
  </link>
  <joint name="shoulder" type="revolute">
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <parent link="base"/>
    <child link="upper"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>
  </joint>
  <link name="upper">
    <inertial>
      <origin xyz="0 0 0.2"/>
      <mass value="1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"/>
    </inertial>
    <collision>
      <geometry><box size="0.05 0.05 0.4"/></geometry>
    </collision>
  </link>
  <joint name="elbow" type="revolute">
    <origin xyz="0 0 0.4"/>
    <parent link="upper"/>
    <child link="lower"/>
    <axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="5" velocity="3"/>
  </joint>
  <link name="lower">
    <inertial>
      <mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/>
    </inertial>
  </link>
</robot>
"""


def tetra_stl(path: Path) -> Path:
    """A binary STL tetrahedron (4 facets)."""
    v = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = bytearray(b"mpc test tetrahedron".ljust(80, b" "))
    data += struct.pack("<I", len(faces))
    for f in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for i in f:
            data += struct.pack("<3f", *v[i])
        data += struct.pack("<H", 0)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bytes(data))
    return path


def arm(folder: Path, urdf: str = ARM_URDF) -> Path:
    """Write the arm URDF and its mesh into `folder`; the URDF's path."""
    tetra_stl(folder / "meshes" / "tetra.stl")
    return write(folder / "arm.urdf", urdf)
