"""A model release laid out as Phobos 2.x writes one: `urdf/`, `smurf/` with JSON-formatted
`.yml` annotation files (indent 2, sorted keys), `joint_limits.yml`, the PDF, README.md and
manifest.xml. Written for mpc's tests from reading Phobos's exporter
(phobos/core/robot.py `export_smurf`, phobos/io/representation.py, sensor_representations.py);
no file of Phobos is copied.

The model is the four-bar linkage of tests/checks/fourbar.py with a visual and a material
per bar, a camera, a motor on the crank, a loop-closure joint and a submechanism. Phobos's
habits it carries: collisions and visuals listed by name only (their links found through
the URDF, where Phobos names every shape), colours as lists and as `{r, g, b, a}`, offsets
as `{x, y, z}` and `{w, x, y, z}`, materials the URDF only names, derived keys on every
entry (`cut_joint: false`, `constraint_axes: []`, the shape lists of links,
`transparency`), and keys mpc does not model (`noDataPackage`, `reducedDataPackage`, a
camera's `hud_width`, …). Phobos 2.1 (run from its source) reads it, and reads mpc's SMURF
of it to the same sensors, materials, motors, collisions, poses and submechanisms.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

URDF = """\
<?xml version="1.0"?>
<robot name="fourbar" version="1.0">
  <joint name="crank_joint" type="revolute">
    <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.0"/>
    <parent link="base"/>
    <child link="crank"/>
    <axis xyz="0.0 1.0 0.0"/>
    <limit effort="100.0" lower="-3.0" upper="3.0" velocity="5.0"/>
  </joint>
  <joint name="coupler_joint" type="revolute">
    <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 1.0"/>
    <parent link="crank"/>
    <child link="coupler"/>
    <axis xyz="0.0 1.0 0.0"/>
    <limit effort="100.0" lower="-3.0" upper="3.0" velocity="5.0"/>
  </joint>
  <joint name="coupler_tip_joint" type="fixed">
    <origin rpy="0.0 0.0 0.0" xyz="2.0 0.0 0.0"/>
    <parent link="coupler"/>
    <child link="coupler_tip"/>
  </joint>
  <joint name="rocker_joint" type="revolute">
    <origin rpy="0.0 0.0 0.0" xyz="2.0 0.0 0.0"/>
    <parent link="base"/>
    <child link="rocker"/>
    <axis xyz="0.0 1.0 0.0"/>
    <limit effort="100.0" lower="-3.0" upper="3.0" velocity="5.0"/>
  </joint>
  <joint name="rocker_tip_joint" type="fixed">
    <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 1.0"/>
    <parent link="rocker"/>
    <child link="rocker_tip"/>
  </joint>
  <link name="base">
    <inertial>
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.0"/>
      <mass value="5.0"/>
      <inertia ixx="0.1" ixy="0.0" ixz="0.0" iyy="0.1" iyz="0.0" izz="0.1"/>
    </inertial>
    <collision name="base_collision">
      <origin rpy="0.0 0.0 0.0" xyz="1.0 0.0 -0.05"/>
      <geometry>
        <box size="2.2 0.1 0.1"/>
      </geometry>
    </collision>
    <visual name="base_visual">
      <origin rpy="0.0 0.0 0.0" xyz="1.0 0.0 -0.05"/>
      <material name="grey"/>
      <geometry>
        <box size="2.2 0.1 0.1"/>
      </geometry>
    </visual>
  </link>
  <link name="crank">
    <inertial>
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.5"/>
      <mass value="1.0"/>
      <inertia ixx="0.084" ixy="0.0" ixz="0.0" iyy="0.084" iyz="0.0" izz="0.001"/>
    </inertial>
    <collision name="crank_collision">
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.5"/>
      <geometry>
        <box size="0.05 0.05 1.0"/>
      </geometry>
    </collision>
    <visual name="crank_visual">
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.5"/>
      <material name="orange"/>
      <geometry>
        <box size="0.05 0.05 1.0"/>
      </geometry>
    </visual>
  </link>
  <link name="coupler">
    <inertial>
      <origin rpy="0.0 0.0 0.0" xyz="1.0 0.0 0.0"/>
      <mass value="2.0"/>
      <inertia ixx="0.001" ixy="0.0" ixz="0.0" iyy="0.67" iyz="0.0" izz="0.67"/>
    </inertial>
    <collision name="coupler_collision">
      <origin rpy="0.0 0.0 0.0" xyz="1.0 0.0 0.0"/>
      <geometry>
        <box size="2.0 0.05 0.05"/>
      </geometry>
    </collision>
  </link>
  <link name="coupler_tip"/>
  <link name="rocker">
    <inertial>
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.5"/>
      <mass value="3.0"/>
      <inertia ixx="0.25" ixy="0.0" ixz="0.0" iyy="0.25" iyz="0.0" izz="0.001"/>
    </inertial>
    <collision name="rocker_collision">
      <origin rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.5"/>
      <geometry>
        <box size="0.05 0.05 1.0"/>
      </geometry>
    </collision>
  </link>
  <link name="rocker_tip"/>
</robot>
"""

NO_DATA = {"noDataPackage": False, "reducedDataPackage": False}


def _link(name: str, collisions: list[str], visuals: list[str]) -> dict[str, Any]:
    return {"name": name, "collisions": collisions, "visuals": visuals, **NO_DATA}


def _joint(name: str, parent: str, child: str, kind: str) -> dict[str, Any]:
    return {"name": name, "parent": parent, "child": child, "joint_type": kind, "cut_joint": False,
            "constraint_axes": [], **NO_DATA}


ANNOTATIONS: dict[str, Any] = {
    "links": [_link("base", ["base_collision"], ["base_visual"]),
              _link("crank", ["crank_collision"], ["crank_visual"]),
              _link("coupler", ["coupler_collision"], []), _link("coupler_tip", [], []),
              {**_link("rocker", ["rocker_collision"], []), "mass_tolerance": 0.01},
              _link("rocker_tip", [], [])],
    "joints": [_joint("crank_joint", "base", "crank", "revolute"),
               {**_joint("coupler_joint", "crank", "coupler", "revolute"), "damping_estimate": 0.2},
               _joint("coupler_tip_joint", "coupler", "coupler_tip", "fixed"),
               _joint("rocker_joint", "base", "rocker", "revolute"),
               _joint("rocker_tip_joint", "rocker", "rocker_tip", "fixed"),
               {"name": "loop", "parent": "coupler_tip", "child": "rocker_tip", "joint_type": "revolute",
                "cut_joint": True, "constraint_axes": [{"name": "y", "axis": [0.0, 1.0, 0.0]}],
                "origin": {"position": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0],
                           "relative_to": "coupler_tip"}}],
    # by name only, as Phobos wrote them in 2022
    "collisions": [{"name": "base_collision", **NO_DATA},
                   {"name": "crank_collision", "bitmask": 3, **NO_DATA},
                   {"name": "coupler_collision", "bitmask": 5, **NO_DATA},
                   {"name": "rocker_collision", "link": "rocker", "bitmask": 9, **NO_DATA}],
    "visuals": [{"name": "base_visual", "link": "base", "lod": 1},
                {"name": "crank_visual", "link": "crank", "lod": 0}],
    "materials": [  # colours as lists (older Phobos) and as mappings (Phobos 2.x)
        {"name": "grey", "diffuseColor": [0.5, 0.5, 0.5, 1.0], "ambientColor": [0.8, 0.8, 0.8, 1.0],
         "specularColor": [0.4980392156862745, 0.4980392156862745, 0.4980392156862745, 1.0],
         "shininess": 40.0, "transparency": 0.0},
        {"name": "orange", "diffuseColor": {"r": 1.0, "g": 0.5, "b": 0.0, "a": 1.0},
         "emissionColor": {"r": 0.1, "g": 0.05, "b": 0.0, "a": 1.0}, "transparency": 0.0}],
    "motors": [{"name": "crank_motor", "joint": "crank_joint", "type": "position", "maxEffort": 100.0,
                "maxSpeed": 5.0, "maxValue": 3.0, "minValue": -3.0, "p": 30.0}],
    "sensors": [{"name": "camera_on_rocker", "type": "CameraSensor", "link": "rocker_tip", "width": 640,
                 "height": 480, "hud_width": 320, "hud_height": 240, "opening_width": 90,
                 "opening_height": 90, "depth_image": 0, "show_cam": 1, "frame_offset": 1,
                 "position_offset": {"x": 0.0, "y": 0.0, "z": 0.25},
                 "orientation_offset": {"w": 0.7071067811865476, "x": 0.0, "y": 0.7071067811865476,
                                        "z": 0.0}}],
    "poses": [{"name": "tilted", "joints": {"crank_joint": 0.3, "coupler_joint": -0.3, "rocker_joint": 0.3}}],
}

SUBMECHANISMS = {"submechanisms": [{
    "name": "fourbar", "contextual_name": "four_bar_linkage", "type": "4BAR",
    "jointnames": ["coupler_joint", "coupler_tip_joint", "crank_joint", "rocker_joint", "rocker_tip_joint"],
    "jointnames_spanningtree": ["crank_joint", "coupler_joint", "rocker_joint"],
    "jointnames_active": ["crank_joint"], "jointnames_independent": ["crank_joint"]}]}

JOINT_LIMITS = {"limits": {
    "names": ["crank_joint", "coupler_joint", "rocker_joint"],
    "elements": [{"max": {"position": 3.0, "speed": 5.0, "effort": 100.0}, "min": {"position": -3.0}}] * 3}}


def dump_json(data: Any) -> str:
    """Phobos's `dump_json`: JSON, indent 2, sorted keys, in a `.yml` file."""
    return json.dumps(data, indent=2, sort_keys=True)


def write_release(folder: Path, name: str = "fourbar") -> Path:
    """Write the release into `folder`; returns its `.smurf`."""
    (folder / "urdf").mkdir(parents=True, exist_ok=True)
    (folder / "smurf").mkdir(exist_ok=True)
    (folder / "urdf" / f"{name}.urdf").write_text(URDF)
    files = [f"../urdf/{name}.urdf"]
    for category, content in {**ANNOTATIONS, "submechanisms": SUBMECHANISMS}.items():
        data = content if category == "submechanisms" else {category: content}
        (folder / "smurf" / f"{name}_{category}.yml").write_text(dump_json(data))
        files.append(f"{name}_{category}.yml")
    smurf = folder / "smurf" / f"{name}.smurf"
    smurf.write_text(dump_json({"modelname": name, "files": sorted(files), "description": "",
                                "additional_files": {}, "version": "1.0.0"}))
    (folder / "joint_limits.yml").write_text(dump_json(JOINT_LIMITS))
    (folder / f"{name}.pdf").write_bytes(b"%PDF-1.4\n%%EOF\n")
    (folder / "README.md").write_text(f"# {name}\n\nBuilt by Phobos CI.\n")
    (folder / "manifest.xml").write_text(f"<package><description>{name}</description></package>\n")
    return smurf
