"""The ROS 2 package files written around a `ros_pathes` export."""

from __future__ import annotations

import math
from pathlib import Path

import yaml
from catkin_pkg.package import parse_package_string
from lxml import etree

from tests.conftest import ERD, Diags, compile_file, write


def test_ros_package_of_a_real_model(tmp_path: Path) -> None:
    """package.xml is a valid format-3 manifest with the model's metadata; CMakeLists.txt
    installs every folder a `package://` path points into; each pose is an init file."""
    source = ERD / "talos_data/robots/talos_left_arm.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: talos-arm
          ros_pkg_name: talos_arm_description
          version: "1.4.2"
          license: BSD-3-Clause
          description: "TALOS left arm & hand"
          input_models: {{arm: {{basefile: "{source}"}}}}
          assemble: {{model: arm}}
          poses:
            home: {{arm_left_2_joint: [deg, 30], arm_left_4_joint: -pi/4}}
          export_config:
            - {{type: urdf, mesh_format: stl, ros_pathes: true}}
            - {{type: sdf, mesh_format: obj}}
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None

    package = parse_package_string((out / "package.xml").read_text())
    package.validate()  # raises on anything REP 149 forbids
    assert (package.package_format, package.name, package.version) == (3, "talos_arm_description", "1.4.2")
    assert package.licenses == ["BSD-3-Clause"]
    assert package.description == "TALOS left arm &amp; hand"  # catkin_pkg returns the XML text
    assert [d.name for d in package.buildtool_depends] == ["ament_cmake"]
    assert package.get_build_type() == "ament_cmake"

    assert (out / "CMakeLists.txt").read_text() == (
        "cmake_minimum_required(VERSION 3.8)\nproject(talos_arm_description)\n\n"
        "find_package(ament_cmake REQUIRED)\n\n"
        "install(DIRECTORY\n  config\n  meshes\n  sdf\n  smurf\n  urdf\n"
        "  DESTINATION share/${PROJECT_NAME}\n)\n\n"
        "ament_package()\n")
    urdf = etree.parse(str(out / "urdf/arm.urdf")).getroot()
    for mesh in urdf.iter("mesh"):
        inside = mesh.get("filename").removeprefix("package://talos_arm_description/")
        assert (out / inside).is_file(), inside

    home = yaml.safe_load((out / "config/init_positions_home.yml").read_text())
    assert home.keys() == {"initial_positions"}
    positions = home["initial_positions"]
    assert positions.keys() == {"arm_left_2_joint", "arm_left_4_joint"}
    assert math.isclose(positions["arm_left_2_joint"], math.radians(30), rel_tol=1e-15)
    assert math.isclose(positions["arm_left_4_joint"], -math.pi / 4, rel_tol=1e-15)


def test_without_ros_pathes_there_is_no_package(tmp_path: Path) -> None:
    source = ERD / "talos_data/robots/talos_left_arm.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: Talos-Arm
          version: "2.1"
          input_models: {{arm: {{basefile: "{source}"}}}}
          assemble: {{model: arm}}
          export_config: [{{type: urdf}}]
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    assert not (out / "package.xml").exists() and not (out / "CMakeLists.txt").exists()
