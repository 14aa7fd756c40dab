"""Small models the tests write themselves: a three-link arm with a real STL mesh."""

from __future__ import annotations

import io
import struct
import tarfile
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


# A robot carrying every name the examples of the reference (model-definitions.md) use.
REFERENCE_JOINTS = [
    ("body_joint_1", "revolute", "root", "body_link_1"),
    ("body_joint_b", "revolute", "body_link_1", "body_link_2"),
    ("body_joint_2", "fixed", "body_link_2", "body_link_3"),
    ("mount_r", "fixed", "root", "right_arm_mount_link"),
    ("mount_l", "fixed", "root", "left_arm_mount_link"),
    ("control", "fixed", "root", "control_frame"),
    ("right_arm_joint", "revolute", "right_arm_mount_link", "right_arm_link"),
    ("left_arm_shoulder_joint1", "revolute", "left_arm_mount_link", "left_shoulder_1"),
    ("left_arm_shoulder_joint2", "revolute", "left_shoulder_1", "left_shoulder_2"),
    ("left_exo_shoulder_1_joint", "revolute", "root", "exo_1"),
    ("slider", "prismatic", "root", "slider_link"),
    ("LLHip3", "revolute", "root", "ll_hip"), ("LLKnee", "revolute", "ll_hip", "ll_knee"),
    ("LLAnklePitch", "revolute", "ll_knee", "ll_ankle"),
    ("LLAnkle_ft_joint", "fixed", "ll_ankle", "LLAnkle_FT"),
    ("LRHip3", "revolute", "root", "lr_hip"), ("LRKnee", "revolute", "lr_hip", "lr_knee"),
    ("LRAnklePitch", "revolute", "lr_knee", "lr_ankle"),
    ("ALShoulder1", "revolute", "root", "al_1"), ("ALShoulder2", "revolute", "al_1", "al_2"),
    ("ALElbow", "revolute", "al_2", "al_3"),
    ("ARShoulder1", "revolute", "root", "ar_1"), ("ARShoulder2", "revolute", "ar_1", "ar_2"),
    ("ARElbow", "revolute", "ar_2", "ar_3"),
    ("BodyPitch", "revolute", "root", "body_p"), ("BodyRoll", "revolute", "body_p", "body_r"),
    ("Body_B11", "revolute", "body_r", "b11"), ("Body_B12", "revolute", "b11", "b12"),
    ("Body_Act1", "prismatic", "b12", "act1"), ("Body_B21", "revolute", "body_r", "b21"),
    ("Body_B22", "revolute", "b21", "b22"), ("Body_Act2", "prismatic", "b22", "act2"),
]
REFERENCE_COLLISIONS = {"body_link_1": "body_joint_1_collision",
                        "right_arm_mount_link": "right_arm_mount_link_collision",
                        "left_arm_mount_link": "left_arm_mount_link_collision",
                        "right_arm_link": "right_arm_link_collision"}


def reference_robot(path: Path) -> Path:
    """Write the reference robot URDF to `path`: small boxes, 0.1 m apart, axes along z
    (the two shoulder joints' axes meet, as move_joint_axis_to_intersection needs)."""
    links = ["root"] + [child for _, _, _, child in REFERENCE_JOINTS]
    out = ['<?xml version="1.0"?>', '<robot name="mighty_bust">']
    for i, name in enumerate(links):
        collision = ""
        if name in REFERENCE_COLLISIONS:
            collision = (f'<collision name="{REFERENCE_COLLISIONS[name]}"><origin xyz="0 0 {0.01 * i}"/>'
                         '<geometry><box size="0.02 0.02 0.02"/></geometry></collision>')
        out.append(f'  <link name="{name}"><inertial><origin xyz="0 0 0.01"/><mass value="0.5"/>'
                   '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
                   f'{collision}</link>')
    for name, kind, parent, child in REFERENCE_JOINTS:
        axis = "1 0 0" if name == "left_arm_shoulder_joint2" else "0 0 1"
        xyz = "0 0 0.05" if name == "left_arm_shoulder_joint2" else "0.1 0 0"
        limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind != "fixed" else ""
        out.append(f'  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                   f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit}</joint>')
    out.append("</robot>")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out) + "\n")
    return path


def tar_archive(*members: tuple[str, bytes | str]) -> tarfile.TarFile:
    """A tar, open for reading, of files (bytes: their data) and symbolic links (str: the
    link's target), each by its name in the archive."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w") as tar:
        for name, content in members:
            info = tarfile.TarInfo(name)
            if isinstance(content, str):
                info.type, info.linkname = tarfile.SYMTYPE, content
                tar.addfile(info)
            else:
                info.size = len(content)
                tar.addfile(info, io.BytesIO(content))
    buffer.seek(0)
    return tarfile.open(fileobj=buffer)
