"""The urdf/sdf export options of issue 7: correct_inertials, copy_with_other_pathes,
ros_pathes in sdf and submodel exports, append_export_config — on example-robot-data models."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from tests.conftest import ERD, Diags, compile_file, write

# The SMURF files of every ur5 output: the categories it has elements of, as Phobos writes them.
UR5_SMURF = ("ur5_collisions.yml", "ur5_joints.yml", "ur5_links.yml", "ur5_visuals.yml")

def _spec(tmp_path: Path, source: Path, exports: str, extra: str = "", name: str = "m.yml") -> Path:
    return write(tmp_path / name, f"""
        model:
          robotname: robot
          modelname: robot_model
          input_models: {{base: {{basefile: "{source}"}}}}
          assemble: {{model: base}}
        {extra}
          export_config:
        {exports}
        """)


def _inertials(urdf: Path) -> dict[str, bytes]:
    """Each link's <inertial> element, as written."""
    root = etree.parse(str(urdf)).getroot()
    return {link.get("name"): etree.tostring(link.find("inertial")) for link in root.iter("link")
            if link.find("inertial") is not None}


def _pin_inertias(urdf: Path) -> dict[str, object]:
    """Each link's inertial as a Pinocchio Inertia (mass, COM, tensor about the COM)."""
    import pinocchio as pin

    out = {}
    for link in etree.parse(str(urdf)).getroot().iter("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        tensor = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]],
                           [i["ixz"], i["iyz"], i["izz"]]])
        origin = inertial.find("origin")
        com = np.array([float(x) for x in origin.get("xyz", "0 0 0").split()]) if origin is not None \
            else np.zeros(3)
        out[link.get("name")] = pin.Inertia(float(inertial.find("mass").get("value")), com, tensor)
    return out


def _physical(inertia: object) -> bool:
    """Pinocchio's pseudo-inertia is positive-definite exactly when the body is physically
    consistent: positive mass, a positive-definite tensor, the triangle inequality."""
    return bool(np.linalg.eigvalsh(inertia.toPseudoInertia().toMatrix()).min() > 0)  # type: ignore[attr-defined]


@pytest.mark.parametrize(("source", "fixed"), [
    ("talos_data/robots/talos_left_arm.urdf", ["wrist_left_ft_link", "wrist_left_ft_tool_link"]),
    ("allegro_hand_description/urdf/allegro_right_hand.urdf",
     ["link_3.0", "link_7.0", "link_11.0", "link_15.0"]),
    ("pr2_description/urdf/pr2.urdf", ["sensor_mount_link", "double_stereo_link"]),
])
def test_correct_inertials_fixes_the_offenders_and_nothing_else(tmp_path: Path, source: str,
                                                                 fixed: list[str]) -> None:
    """talos: a link with mass and a zero tensor; allegro, pr2: tensors that violate the
    triangle inequality. Each becomes physical (checked with Pinocchio); every other
    link's inertial is written byte for byte as without the option."""
    spec = _spec(tmp_path, ERD / source, """
            - {type: urdf, correct_inertials: true}
            - {type: urdf, filename_suffix: _as_given}
        """)
    diags = Diags()
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    warning = diags.take("W0530", severity=diags.diagnostics[0].severity)
    assert warning.message == (f"correct_inertials made the inertials of {len(fixed)} link"
                               f"{'s' if len(fixed) > 1 else ''} physical: "
                               + ", ".join(f"'{n}'" for n in fixed))
    corrected, given = out / "urdf/robot.urdf", out / "urdf/robot_as_given.urdf"
    before, after = _pin_inertias(given), _pin_inertias(corrected)
    assert not any(_physical(before[n]) for n in fixed)
    for name, inertia in after.items():
        if inertia.mass > 0 or name in fixed:  # type: ignore[attr-defined]
            assert _physical(inertia), name
    written, original = _inertials(corrected), _inertials(given)
    assert sorted(n for n in written if written[n] != original[n]) == sorted(fixed)
    for name in fixed:  # masses and COM kept; the tensor's principal axes kept
        assert after[name].mass == before[name].mass  # type: ignore[attr-defined]
        assert np.array_equal(after[name].lever, before[name].lever)  # type: ignore[attr-defined]
        difference = after[name].inertia - before[name].inertia  # type: ignore[attr-defined]
        assert np.allclose(difference, difference[0, 0] * np.eye(3), rtol=0, atol=1e-15)


def test_correct_inertials_changes_no_physical_model(tmp_path: Path, diags: Diags) -> None:
    """ur5: every link physical, so the corrected URDF is the same file, and no warning."""
    spec = _spec(tmp_path, ERD / "ur_description/urdf/ur5_robot.urdf", """
            - {type: urdf, correct_inertials: true}
            - {type: urdf, filename_suffix: _as_given}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    assert (out / "urdf/robot.urdf").read_bytes() == (out / "urdf/robot_as_given.urdf").read_bytes()


def test_a_massless_frame_stays_massless(tmp_path: Path) -> None:
    """Mass 0 with a zero tensor is a frame (Phobos gives it 1e-5 kg); mass 0 with a
    tensor gets Phobos's 1e-5 kg; a negative principal moment is lifted."""
    from mpc.ir.physical import corrected
    from mpc.ir.robot import Inertia, Inertial

    zero = Inertia(ixx=0.0, ixy=0.0, ixz=0.0, iyy=0.0, iyz=0.0, izz=0.0)
    assert corrected(Inertial(mass=0.0, inertia=zero)) is None
    massless = corrected(Inertial(mass=0.0, inertia=Inertia(ixx=1.0, ixy=0.0, ixz=0.0, iyy=1.0,
                                                            iyz=0.0, izz=1.0)))
    assert massless is not None and massless.mass == 1e-5 and massless.inertia.ixx == 1.0
    point = corrected(Inertial(mass=0.1, inertia=zero))
    assert point is not None and (point.inertia.ixx, point.inertia.iyy, point.inertia.izz) == (1e-5,) * 3
    negative = corrected(Inertial(mass=1.0, inertia=Inertia(ixx=-0.1, ixy=0.0, ixz=0.0, iyy=1.0,
                                                            iyz=0.0, izz=1.0)))
    assert negative is not None
    assert (negative.inertia.ixx, negative.inertia.iyy) == pytest.approx((0.001, 1.101))


def test_copy_with_other_pathes_writes_phobos_files(tmp_path: Path, diags: Diags) -> None:
    """A relative-path URDF gets `<name>_ros.urdf`, a ros_pathes SDF gets `<name>_relpath.sdf`;
    the copies differ from their file only in the mesh paths, and the package:// paths
    name the package that the written package.xml declares."""
    spec = _spec(tmp_path, ERD / "talos_data/robots/talos_left_arm.urdf", """
            - {type: urdf, mesh_format: stl, copy_with_other_pathes: true}
            - {type: sdf, mesh_format: stl, ros_pathes: true, copy_with_other_pathes: true}
        """, extra="  ros_pkg_name: talos_arm")
    out = compile_file(spec, tmp_path / "out", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert out is not None
    assert sorted(p.name for p in (out / "urdf").iterdir()) == ["robot.urdf", "robot_ros.urdf"]
    assert sorted(p.name for p in (out / "sdf").iterdir()) == [
        "model.config", "robot.sdf", "robot_relpath.sdf"]
    urdf, ros = (out / "urdf/robot.urdf").read_text(), (out / "urdf/robot_ros.urdf").read_text()
    assert 'filename="../meshes/stl/' in urdf and "package://" not in urdf
    assert ros == urdf.replace('filename="../meshes/', 'filename="package://talos_arm/meshes/')
    sdf, rel = (out / "sdf/robot.sdf").read_text(), (out / "sdf/robot_relpath.sdf").read_text()
    assert "<uri>package://talos_arm/meshes/stl/" in sdf and "<uri>../" not in sdf
    assert rel == sdf.replace("<uri>package://talos_arm/meshes/", "<uri>../meshes/")
    assert "<name>talos_arm</name>" in (out / "package.xml").read_text()
    # Every package:// path points at a file of the package.
    for uri in etree.parse(str(out / "sdf/robot.sdf")).getroot().iter("uri"):
        assert (out / uri.text.removeprefix("package://talos_arm/")).is_file()
    # The linked URDF is still the relative one; the copies are beside it.
    assert "../urdf/robot.urdf" in (out / "smurf/robot.smurf").read_text()


def test_the_ros_copy_loads_in_pinocchio_through_the_package(tmp_path: Path, diags: Diags) -> None:
    import pinocchio as pin

    spec = _spec(tmp_path, ERD / "ur_description/urdf/ur5_robot.urdf", """
            - {type: urdf, mesh_format: stl, copy_with_other_pathes: true}
        """)
    out = compile_file(spec, tmp_path / "pkg" / "robot_model", diags).out
    assert out is not None
    ros = str(out / "urdf/robot_ros.urdf")
    model = pin.buildModelFromUrdf(ros)
    visual = pin.buildGeomFromUrdf(model, ros, pin.GeometryType.VISUAL, package_dirs=[str(tmp_path / "pkg")])
    assert visual.ngeoms > 0
    assert all(Path(g.meshPath).is_file() and str(out) in g.meshPath for g in visual.geometryObjects)


def test_ros_pathes_in_a_submodel_point_into_its_folder(tmp_path: Path, diags: Diags) -> None:
    spec = _spec(tmp_path, ERD / "ur_description/urdf/ur5_robot.urdf", """
            - {type: urdf, mesh_format: stl}
            - type: submodel
              name: forearm
              start: forearm_link
              export_config:
                - {type: urdf, mesh_format: stl, ros_pathes: true, copy_with_other_pathes: true}
                - {type: sdf, mesh_format: stl, ros_pathes: true}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert out is not None
    sub = out / "submodels/forearm"
    files = ((sub / "urdf/forearm.urdf", "mesh", "filename"), (sub / "sdf/forearm.sdf", "uri", None))
    for path, tag, attr in files:
        names = [e.get(attr) if attr else e.text for e in etree.parse(str(path)).getroot().iter(tag)]
        prefix = "package://robot_model/submodels/forearm/meshes/stl/"
        assert names and all(n.startswith(prefix) for n in names)
        assert all((out / n.removeprefix("package://robot_model/")).is_file() for n in names)
    rel = (sub / "urdf/forearm_relpath.urdf").read_text()
    assert 'filename="../meshes/stl/' in rel and "package://" not in rel
    assert (out / "package.xml").is_file()


def test_append_export_config_extends_the_inherited_list(tmp_path: Path, diags: Diags) -> None:
    """The defaults file's export_config, then the model's append_export_config; a second
    model with the same defaults does not see the first one's additions (Phobos's
    append changed the shared default list in place)."""
    source = ERD / "ur_description/urdf/ur5_robot.urdf"
    write(tmp_path / "base.yml", f"""
        default_model:
          input_models: {{base: {{basefile: "{source}"}}}}
          assemble: {{model: base}}
          export_config:
            - {{type: urdf, mesh_format: stl}}
        """)
    first = write(tmp_path / "first.yml", """
        defaults: base.yml
        model:
          robotname: ur5
          modelname: first
          append_export_config:
            - {type: urdf, mesh_format: obj, filename_suffix: _obj}
            - {type: joint_limits}
        """)
    second = write(tmp_path / "second.yml",
                   "defaults: base.yml\nmodel: {robotname: ur5, modelname: second}\n")
    out = compile_file(first, tmp_path / "first", diags).out
    assert out is not None
    assert sorted(p.name for p in (out / "urdf").iterdir()) == ["ur5.urdf", "ur5_obj.urdf"]
    assert (out / "joint_limits.yml").is_file()
    out2 = compile_file(second, tmp_path / "second", diags).out
    assert out2 is not None
    assert sorted(p.name for p in (out2 / "urdf").iterdir()) == ["ur5.urdf"]
    assert not (out2 / "joint_limits.yml").exists()


def test_append_export_config_without_export_config_adds_to_the_default_urdf(tmp_path: Path,
                                                                            diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: ur5
          modelname: ur5_model
          input_models: {{base: {{basefile: "{ERD / 'ur_description/urdf/ur5_robot.urdf'}"}}}}
          assemble: {{model: base}}
          append_export_config:
            - {{type: sdf, mesh_format: stl}}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert out is not None
    assert (out / "urdf/ur5.urdf").is_file() and (out / "sdf/ur5.sdf").is_file()


def test_inherit_smurf_properties_false_drops_the_derived_inputs_smurf_data(tmp_path: Path,
                                                                             diags: Diags) -> None:
    """The ur5 with motors, sensors, poses, submechanisms, annotations and bitmasks, taken
    as a derived_base: with `inherit_smurf_properties: false` the SMURF of the new model
    links its URDF and nothing else, and the URDF is the parent's, byte for byte; the new
    model's own annotations are kept."""
    from tests.backends.test_smurf import UR5, child

    write(tmp_path / "ur5.yml", UR5)
    write(tmp_path / "plain.yml", child("derived_base", "ur5.yml").replace(
        "  version: 1.2.0\n", "  version: 1.2.0\n  inherit_smurf_properties: false\n"))
    write(tmp_path / "own.yml", child("derived_base", "ur5.yml").replace(
        "  version: 1.2.0\n", "  version: 1.2.0\n  inherit_smurf_properties: false\n"
        "  poses:\n    rest: {elbow_joint: 0.5}\n"))
    outs = {}
    for name in ("ur5", "plain", "own"):
        outs[name] = compile_file(tmp_path / f"{name}.yml", tmp_path / "out" / name, diags).out
        assert outs[name] is not None
        diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert sorted(p.name for p in (outs["plain"] / "smurf").iterdir()) == ["ur5.smurf", *UR5_SMURF]
    assert (outs["plain"] / "urdf/ur5.urdf").read_bytes() == (outs["ur5"] / "urdf/ur5.urdf").read_bytes()
    assert sorted(p.name for p in (outs["own"] / "smurf").iterdir()) == [
        "ur5.smurf", *UR5_SMURF[:3], "ur5_poses.yml", UR5_SMURF[3]]
    assert "rest" in (outs["own"] / "smurf/ur5_poses.yml").read_text()
    assert "home" not in (outs["own"] / "smurf/ur5_poses.yml").read_text()


def test_inherit_smurf_properties_false_without_a_derived_input(tmp_path: Path, diags: Diags) -> None:
    spec = _spec(tmp_path, ERD / "ur_description/urdf/ur5_robot.urdf", "    - {type: urdf}",
                 extra="  inherit_smurf_properties: false")
    assert compile_file(spec, tmp_path / "out", diags).out is not None
    warning = diags.take("W0531", severity=diags.diagnostics[0].severity)
    assert warning.message == ("'inherit_smurf_properties: false' has no effect: no input model is a "
                               "derived_base")
    assert (warning.span.line, warning.span.col) == (6, 3)


def test_the_smurf_lists_the_submodels_and_reads_them_back(tmp_path: Path, diags: Diags) -> None:
    """`smurf/<name>_submodels.yml` holds each submodel's definition with Phobos's keys and
    its folder relative to smurf/; a model read from that SMURF writes the same files."""
    import yaml

    source = ERD / "ur_description/urdf/ur5_robot.urdf"
    spec = write(tmp_path / "s.yml", f"""
        model:
          robotname: ur5
          modelname: ur5_model
          input_models: {{ur5: {{basefile: "{source}"}}}}
          assemble: {{model: ur5}}
          export_config:
            - {{type: urdf, mesh_format: stl}}
            - {{type: submodel, name: forearm, start: forearm_link, remove_fixed: true}}
            - {{type: submodel, name: arm, stop: [wrist_1_link]}}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    index = yaml.safe_load((out / "smurf/ur5.smurf").read_text())
    assert index["files"] == ["../urdf/ur5.urdf", *UR5_SMURF[:3], "ur5_submodels.yml", UR5_SMURF[3]]
    submodels = yaml.safe_load((out / "smurf/ur5_submodels.yml").read_text())["submodels"]
    assert submodels["arm"] == {
        "name": "arm", "robotname": "arm", "start": None, "stop": ["wrist_1_link"], "abstract_model": False,
        "remove_joints": [], "move_joint_axis_to_intersection": None, "include_unstopped_branches": False,
        "no_submechanisms": False, "include_human_in_abstract": False, "export_dir": "../submodels/arm"}
    assert submodels["forearm"]["start"] == "forearm_link" and submodels["forearm"]["remove_fixed"] is True
    for name, definition in submodels.items():
        assert (out / "smurf" / definition["export_dir"] / "urdf" / f"{name}.urdf").is_file()
    assert not (out / "submodels/arm/smurf/arm_submodels.yml").exists()
    again = write(tmp_path / "r.yml", f"""
        model:
          robotname: ur5
          modelname: ur5_model
          input_models: {{ur5: {{basefile: "{out / 'smurf/ur5.smurf'}"}}}}
          assemble: {{model: ur5}}
          export_config:
            - {{type: urdf, mesh_format: stl}}
        """)
    out2 = compile_file(again, tmp_path / "again", diags).out
    assert out2 is not None
    for name in ("ur5.smurf", "ur5_submodels.yml"):
        assert (out2 / "smurf" / name).read_bytes() == (out / "smurf" / name).read_bytes()


def test_float_fmt_dict_formats_the_named_numbers(tmp_path: Path, diags: Diags) -> None:
    """talos's arm with `%.6f` for every number and `%.3e` for ixx in the URDF, `%.4f` for
    poses in the SDF: those numbers are written so, the others exactly; a second build gives
    the same bytes; Pinocchio reads the same model to the formats' precision."""
    import pinocchio as pin

    spec = _spec(tmp_path, ERD / "talos_data/robots/talos_left_arm.urdf", """
            - {type: urdf, mesh_format: stl, float_fmt_dict: {default: "%.6f", ixx: "%.3e"}}
            - {type: urdf, mesh_format: stl, filename_suffix: _exact}
            - {type: sdf, mesh_format: stl, float_fmt_dict: {pose: "%.4f"}}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert out is not None
    root = etree.parse(str(out / "urdf/robot.urdf")).getroot()
    for tag, attr in (("origin", "xyz"), ("origin", "rpy"), ("mass", "value"), ("limit", "effort"),
                      ("inertia", "iyy"), ("axis", "xyz")):
        for element in root.iter(tag):
            if element.get(attr) is not None:
                numbers = element.get(attr).split()
                assert all(re.fullmatch(r"-?\d+\.\d{6}", x) for x in numbers), element.get(attr)
    assert all(re.fullmatch(r"-?\d\.\d{3}e[-+]\d\d", e.get("ixx")) for e in root.iter("inertia"))
    assert {e.get("link") for e in root.iter("parent")} <= {link.get("name") for link in root.iter("link")}
    sdf = etree.parse(str(out / "sdf/robot.sdf")).getroot()
    assert all(re.fullmatch(r"(-?\d+\.\d{4} ){5}-?\d+\.\d{4}", p.text) for p in sdf.iter("pose"))
    assert [m.text for m in sdf.iter("mass")] == [  # exact: no format for them
        m.get("value") for m in etree.parse(str(out / "urdf/robot_exact.urdf")).getroot().iter("mass")]
    first = {p: p.read_bytes() for p in sorted(out.rglob("*.*df"))}
    again = compile_file(spec, tmp_path / "again", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert again is not None
    assert {p.relative_to(out): b for p, b in first.items()} == {
        p.relative_to(again): p.read_bytes() for p in sorted(again.rglob("*.*df"))}
    formatted = pin.buildModelFromUrdf(str(out / "urdf/robot.urdf"))
    exact = pin.buildModelFromUrdf(str(out / "urdf/robot_exact.urdf"))
    placements = [(a, b) for a, b in zip(formatted.jointPlacements, exact.jointPlacements, strict=True)]
    assert all(np.allclose(a.homogeneous, b.homogeneous, atol=1e-6) for a, b in placements)
    assert all(abs(a.mass - b.mass) <= 5e-7 for a, b in zip(formatted.inertias, exact.inertias, strict=True))
    assert any(a.mass != b.mass or not np.array_equal(a.inertia, b.inertia)
               for a, b in zip(formatted.inertias, exact.inertias, strict=True))


def test_sdf_additional_meshes_and_enforce_zero(tmp_path: Path, diags: Diags) -> None:
    """As for URDF: the meshes also in OBJ, referenced by nothing; 1e-17 written as 0."""
    spec = _spec(tmp_path, ERD / "talos_data/robots/talos_left_arm.urdf", """
            - {type: sdf, mesh_format: stl, additional_meshes: [obj], enforce_zero: true}
            - {type: sdf, mesh_format: stl, filename_suffix: _as_is}
        """, extra="  frames:\n            arm_left_2_link: {transform_frame: {xyz: [0, 0, 1e-17]}}")
    out = compile_file(spec, tmp_path / "out", diags).out
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    diags.take("W0500", severity=diags.diagnostics[0].severity)
    assert out is not None
    assert sorted(p.stem for p in (out / "meshes/obj").iterdir()) == sorted(
        p.stem for p in (out / "meshes/stl").iterdir())
    zeroed, as_is = (out / "sdf/robot.sdf").read_text(), (out / "sdf/robot_as_is.sdf").read_text()
    assert "1e-17" in as_is and "1e-17" not in zeroed and "/obj/" not in zeroed


def test_from_the_command_line(tmp_path: Path) -> None:
    """pr2: `mpc check` is clean, `mpc compile` writes both files of each export and names
    the corrected links in gcc format."""
    from tests.mpc_command import mpc

    spec = _spec(tmp_path, ERD / "pr2_description/urdf/pr2.urdf", """
            - type: urdf
              correct_inertials: true
              copy_with_other_pathes: true
              float_fmt_dict: {default: "%.8g"}
        """, extra="  append_export_config:\n            - {type: joint_limits}")
    check = mpc("check", spec)
    assert (check.returncode, check.stderr) == (0, "")
    run = mpc("compile", "--format", "gcc", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    assert run.stderr == (f"{spec}:10:7: warning: correct_inertials made the inertials of 2 links physical: "
                          "'sensor_mount_link', 'double_stereo_link' [W0530]\n")
    assert run.stdout.startswith(f"compiled '{spec}' into '{tmp_path}/out': CMakeLists.txt, "
                                 "joint_limits.yml, package.xml, smurf/robot.smurf, "
                                 "smurf/robot_collisions.yml, smurf/robot_joints.yml, smurf/robot_links.yml, "
                                 "smurf/robot_materials.yml, "
                                 "smurf/robot_visuals.yml, urdf/robot.urdf, urdf/robot_ros.urdf and ")


def test_a_submodel_inherits_ros_pathes(tmp_path: Path, diags: Diags) -> None:
    """The model's ros_pathes entry, inherited by a submodel: its paths point into its folder."""
    spec = _spec(tmp_path, ERD / "ur_description/urdf/ur5_robot.urdf", """
            - {type: urdf, mesh_format: stl, ros_pathes: true}
            - {type: submodel, name: wrist, start: wrist_1_link}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    urdf = etree.parse(str(out / "submodels/wrist/urdf/wrist.urdf"))
    names = [m.get("filename") for m in urdf.iter("mesh")]
    assert names and all(n.startswith("package://robot_model/submodels/wrist/meshes/stl/") for n in names)
    assert all((out / n.removeprefix("package://robot_model/")).is_file() for n in names)
