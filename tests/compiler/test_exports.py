"""Several exports of one model: each writes its own file, none overwrites another."""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from tests.conftest import Diags, compile_file, write
from tests.fixtures import arm

HEAD = """
model:
  robotname: arm
  modelname: arm-model
  input_models: {arm: {basefile: arm.urdf}}
  assemble: {model: arm}
  export_config:
"""


def test_filename_suffix_keeps_two_urdf_exports_apart(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: urdf, mesh_format: stl}
    - {type: urdf, mesh_format: obj, filename_suffix: _obj}
    - {type: urdf, mesh_format: stl, filename: tool}
""")
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    assert sorted(p.name for p in (out / "urdf").iterdir()) == ["arm.urdf", "arm_obj.urdf", "tool.urdf"]
    mesh = etree.parse(str(out / "urdf/arm_obj.urdf")).getroot().find(".//mesh").get("filename")
    assert mesh == "../meshes/obj/tetra.obj" and (out / "meshes/obj/tetra.obj").is_file()


def test_two_exports_of_one_file_are_refused(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: urdf, mesh_format: stl}
    - {type: urdf, mesh_format: obj}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0503")
    assert d.message == ("two urdf exports would write urdf/arm (Phobos silently let the last one win); "
                         "give one a filename_suffix")
    assert (d.span.line, d.span.col, d.notes[0][0].line) == (9, 7, 8)


def test_a_second_build_reads_every_mesh_from_the_cache(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """talos with STL and OBJ exports: the OBJ meshes are computed once, then only copied."""
    from tests.conftest import ERD

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    spec = write(tmp_path / "t.yml", f"""
        model:
          robotname: talos
          modelname: talos-two-formats
          input_models: {{talos: {{basefile: "{ERD / 'talos_data/robots/talos_full_v2.urdf'}"}}}}
          assemble: {{model: talos}}
          export_config:
            - {{type: urdf, mesh_format: stl}}
            - {{type: urdf, mesh_format: obj, filename_suffix: _obj}}
        """)
    first = compile_file(spec, tmp_path / "a", Diags()).out
    assert first is not None
    # an entry computed again is a new file (renamed into place); a used one is only touched
    cache = {p: p.stat().st_ino for p in (tmp_path / "cache/meshes").rglob("*")
             if p.is_file() and p.name != ".locks"}
    # every OBJ, computed once, and its hash; the STL files are copied; each STL file read by
    # the plain path (specs/files.md), which keeps no normalized form
    assert len([p for p in cache if "normal" not in p.parts]) == 2 * 48
    assert not [p for p in cache if "normal" in p.parts]
    second = compile_file(spec, tmp_path / "b", Diags()).out
    assert second is not None
    again = {p: p.stat().st_ino for p in (tmp_path / "cache/meshes").rglob("*")
             if p.is_file() and p.name != ".locks"}
    assert again == cache  # nothing was computed again
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(second) for p in second.rglob("*") if p.is_file())
    assert all((first / f).read_bytes() == (second / f).read_bytes() for f in files)


def test_urdf_options_and_mesh_ops(tmp_path: Path) -> None:
    """additional_meshes, ros_pathes, enforce_zero; reduce_meshes keeps at most the faces asked;
    apply_scale bakes the scale into the file."""
    import trimesh

    from tests.conftest import ERD

    source = ERD / "talos_data/robots/talos_left_arm.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm-pkg
          ros_pkg_name: arm_pkg
          input_models: {{arm: {{basefile: "{source}"}}}}
          assemble: {{model: arm}}
          reduce_meshes: 300
          apply_scale: true
          frames:
            arm_left_2_link: {{transform_frame: {{xyz: [0, 0, 1e-17]}}}}
          export_config:
            - {{type: urdf, mesh_format: stl, additional_meshes: obj, ros_pathes: true, enforce_zero: true}}
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    root = etree.parse(str(out / "urdf/arm.urdf")).getroot()
    filenames = [m.get("filename") for m in root.iter("mesh")]
    assert filenames and all(f.startswith("package://arm_pkg/meshes/stl/") for f in filenames)
    assert all(m.get("scale") is None for m in root.iter("mesh"))
    assert sorted(p.stem for p in (out / "meshes/obj").iterdir()) == sorted(
        p.stem for p in (out / "meshes/stl").iterdir())
    for stl in (out / "meshes/stl").iterdir():
        assert len(trimesh.load(stl, force="mesh").faces) <= 300
    assert "1e-17" not in (out / "urdf/arm.urdf").read_text()


def test_mjcf_export_from_the_command_line(tmp_path: Path) -> None:
    """A definition with an mjcf export: MuJoCo loads it; its mass is Pinocchio's."""
    import mujoco
    import pinocchio as pin

    from tests.backends.pin_compare import load
    from tests.conftest import ERD

    source = ERD / "solo_description/robots/solo12.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: solo
          modelname: solo-sim
          input_models: {{solo: {{basefile: "{source}"}}}}
          assemble: {{model: solo}}
          export_config:
            - {{type: urdf}}
            - {{type: mjcf}}
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    model = mujoco.MjModel.from_xml_path(str(out / "mjcf/solo.xml"))
    assert abs(mujoco.mj_getTotalmass(model) - pin.computeTotalMass(load(source))) < 1e-9
    assert (out / "meshes/obj").is_dir()  # MuJoCo reads no DAE: mjcf meshes default to OBJ


def test_a_mesh_that_cannot_be_read_names_link_element_and_file(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    (tmp_path / "meshes/tetra.stl").write_bytes(b"solid broken\n this is no STL\n")
    spec = write(tmp_path / "m.yml", HEAD + "    - {type: urdf, mesh_format: obj}\n")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0603")
    assert d.message.startswith(f"cannot compute mesh 'meshes/obj/tetra.obj' of a visual of link 'base' "
                                f"from '{tmp_path}/meshes/tetra.stl': ")
    assert (d.span.file, d.span.line) == (str(tmp_path / "arm.urdf"), 10)


def test_an_sdf_export_is_an_input_again(tmp_path: Path) -> None:
    """solo12 → SDF → a definition with the SDF as basefile → URDF: the same robot."""
    from tests.backends.pin_compare import assert_same_physics
    from tests.conftest import ERD

    source = ERD / "solo_description/robots/solo12.urdf"
    first = write(tmp_path / "a.yml", f"""
        model:
          robotname: solo
          modelname: solo-sdf
          input_models: {{solo: {{basefile: "{source}"}}}}
          assemble: {{model: solo}}
          export_config: [{{type: sdf}}]
        """)
    assert compile_file(first, tmp_path / "a", Diags()).out is not None
    second = write(tmp_path / "b.yml", f"""
        model:
          robotname: solo
          modelname: solo-again
          input_models: {{solo: {{basefile: "{tmp_path / 'a/sdf/solo.sdf'}"}}}}
          assemble: {{model: solo}}
        """)
    out = compile_file(second, tmp_path / "b", Diags()).out
    assert out is not None
    assert_same_physics(source, out / "urdf/solo.urdf")


def test_add_floating_base(tmp_path: Path) -> None:
    """URDF: Pinocchio makes the floating joint a free flyer, so a fixed-base load of the
    export is the free-flyer model of the source; MJCF: a freejoint."""
    import mujoco
    import numpy as np
    import pinocchio as pin

    from tests.backends.pin_compare import load
    from tests.conftest import ERD

    source = ERD / "solo_description/robots/solo12.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: solo
          modelname: solo-free
          input_models: {{solo: {{basefile: "{source}"}}}}
          assemble: {{model: solo}}
          export_config:
            - {{type: urdf, add_floating_base: true}}
            - {{type: mjcf, add_floating_base: true}}
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    free, ours = load(source), pin.buildModelFromUrdf(str(out / "urdf/solo.urdf"))
    assert (ours.nq, ours.nv) == (free.nq, free.nv)
    assert abs(pin.computeTotalMass(ours) - pin.computeTotalMass(free)) < 1e-12
    q = pin.neutral(free)
    np.testing.assert_allclose(pin.computeGeneralizedGravity(ours, ours.createData(), q),
                               pin.computeGeneralizedGravity(free, free.createData(), q), atol=1e-12)
    model = mujoco.MjModel.from_xml_path(str(out / "mjcf/solo.xml"))
    assert model.nq == free.nq and model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE


def test_sdf_loop_closures_with_include_cut_joints(tmp_path: Path) -> None:
    import shutil
    import subprocess

    from mpc.backends import sdf
    from mpc.core.diagnostics import Sink

    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD.replace("  export_config:\n", """  joints:
    loop: {cut_joint: true, parent: base, child: lower, type: ball}
  export_config:
""") + "    - {type: sdf, mesh_format: stl, include_cut_joints: true}\n")
    sink = Diags()
    out = compile_file(spec, tmp_path / "out", sink).out
    assert out is not None
    sink.diagnostics.clear()  # W0500: the URDF-only data left out
    checked = subprocess.run([shutil.which("ign") or "ign", "sdf", "-k", str(out / "sdf/arm.sdf")],
                             capture_output=True, text=True)
    assert "Valid." in checked.stdout, checked.stdout + checked.stderr
    robot = sdf.read(out / "sdf/arm.sdf", Sink())
    assert robot is not None and list(robot.cut_joints) == ["loop"]
    assert robot.cut_joints["loop"].type == "ball"


def test_sdf_sensors(tmp_path: Path) -> None:
    """IMU, camera, lidar and GPS go into their links, a 6-DOF force-torque sensor into the
    joint above its link; sensors over several joints have no SDF type (W0500 says so)."""
    import shutil
    import subprocess

    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD.replace("  export_config:\n", """  sensors:
    - {type: IMU, name: imu, link: upper, position_offset: [0, 0, 0.1]}
    - {type: CameraSensor, name: cam, link: lower}
    - {type: RotatingRaySensor, name: lidar, link: base}
    - {type: Joint6DOF, name: ft, link: lower}
    - {type: JointPosition, name: encoders, targets: All}
  export_config:
""") + "    - {type: sdf, mesh_format: stl}\n")
    sink = Diags()
    out = compile_file(spec, tmp_path / "out", sink).out
    assert out is not None
    warning = next(d for d in sink.diagnostics if d.code == "W0500")
    assert "1 sensor SDF has no type for" in warning.message
    sink.diagnostics.clear()
    root = etree.parse(str(out / "sdf/arm.sdf")).getroot()
    sensors = {s.get("name"): (s.getparent().get("name"), s.get("type")) for s in root.iter("sensor")}
    assert sensors == {"imu": ("upper", "imu"), "cam": ("lower", "camera"), "lidar": ("base", "gpu_lidar"),
                       "ft": ("elbow", "force_torque")}
    checked = subprocess.run([shutil.which("ign") or "ign", "sdf", "-k", str(out / "sdf/arm.sdf")],
                             capture_output=True, text=True)
    assert "Valid." in checked.stdout, checked.stdout + checked.stderr


def test_two_usd_exports_of_one_file_are_refused(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: usd}
    - {type: usd, layout: single}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0503")
    assert d.message == "two usd exports would write usd/arm; give one a filename_suffix"
    assert (d.span.line, d.span.col, d.notes[0][0].line) == (9, 7, 8)


def test_a_usd_export_takes_only_its_own_keys(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """
    - {type: usd, layout: flat, mesh_format: stl}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert diags.take_error("E0201").message == "unknown key 'mesh_format' in a usd export"
    assert diags.take_error("E0203").message == "'layout' must be one of 'layered' or 'single', got 'flat'"
