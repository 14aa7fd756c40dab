"""SMURF: written beside every model, read back as an input, identical after a round trip.

Round trips run on real example-robot-data models carrying every kind of SMURF data
(motors, sensors, poses, loop closures, submechanisms, annotations, bitmasks): emit →
read → emit gives the same bytes. From the command line, the annotations of a definition
survive a `derived_base` hop and a `basefile:` pointing at its `.smurf`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from mpc.backends import smurf, smurf_reader, urdf
from mpc.core.diagnostics import Severity, Sink
from mpc.core.span import Span
from mpc.ir.extras import CutJoint, Motor, Sensor, Submechanism
from mpc.ir.kinematics import link_in_root
from mpc.ir.program import SmurfExport, UrdfExport
from mpc.ir.robot import Material, Pose, Robot
from tests.conftest import ERD, Diags, write
from tests.fixtures import arm
from tests.mpc_command import mpc

SPAN = Span("test.yml", 1, 1)
MODELS = {
    "talos": ERD / "talos_data/robots/talos_full_v2.urdf",   # 50+ links, mimic joints
    "panda": ERD / "panda_description/urdf/panda.urdf",      # mimic finger
    "ur5": ERD / "ur_description/urdf/ur5_robot.urdf",
    "baxter": ERD / "baxter_description/urdf/baxter.urdf",   # many links, named shapes
}


def annotated(robot: Robot) -> Robot:
    """`robot` with SMURF data on every kind of element (as the definition sections add it)."""
    movable = [n for n, j in robot.joints.items() if j.type != "fixed"]
    links = dict(robot.links)
    for i, (name, link) in enumerate(robot.links.items()):
        links[name] = replace(
            link, annotations={"index_hint": i},
            collisions=tuple(replace(c, bitmask=(i * 7 + k) % 65536, annotations={"ccfm": 0.002})
                             for k, c in enumerate(link.collisions)),
            visuals=tuple(replace(v, annotations={"lod": k}) for k, v in enumerate(link.visuals)))
    joints = {n: replace(j, annotations={"noDataPackage": False}) if n in movable[:3] else j
              for n, j in robot.joints.items()}
    a, b = sorted(robot.links)[:2]
    X = link_in_root(robot, b)
    cut = CutJoint(name="loop", type="ball", parent=a, child=b,
                   origin=Pose((float(X[0, 3]), float(X[1, 3]), 0.1), (0.0, 0.25, -1e-05)),
                   constraint_axes=(("x", (1.0, 0.0, 0.0)), (None, (0.0, 0.0, 1.0))))
    return replace(
        robot, links=links, joints=joints, cut_joints={"loop": cut},
        motors={f"{j}_motor": Motor(name=f"{j}_motor", joint=j, settings={"p": 20.0, "i": 0.001, "d": 0})
                for j in movable},
        sensors={"imu": Sensor(name="imu", type="IMU", link=robot.root, position_offset=(0.0, 0.0, 0.05),
                               annotations={"rate": 100}),
                 "encoders": Sensor(name="encoders", type="JointPosition", targets=tuple(movable))},
        poses={"home": {j: 0.1 * k for k, j in enumerate(movable)}},
        submechanisms=(Submechanism(name="chain", definition={
            "name": "chain", "type": "serial", "jointnames_spanningtree": movable[:2],
            "jointnames_active": movable[:2]}),),
        materials={**robot.materials, "shiny": Material(name="shiny", rgba=(0.0, 0.0, 1.0, 1.0),
                                                        specular=(1.0, 1.0, 1.0), shininess=20.0,
                                                        annotations={"kind": "metal"})},
        annotations={"thermal": {robot.root: {"max_temperature": 60}}, "annotations": {"maintainer": "x"}})


def emitted(robot: Robot, out: Path, sink: Sink) -> dict[str, bytes]:
    """The URDF and SMURF files of `robot` (meshes as the model has them), by path."""
    urdf.emit(robot, UrdfExport(mesh_format="input_type", span=SPAN), out, sink)
    smurf.emit(robot, SmurfExport(span=SPAN, model_file=f"urdf/{robot.name}.urdf", version="1.0.0",
                                  description="round trip"), out, sink)
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and p.parts[len(out.parts)] in ("urdf", "smurf")}


@pytest.mark.parametrize("model", sorted(MODELS))
def test_round_trip_is_byte_identical(model: str, tmp_path: Path, diags: Diags) -> None:
    robot = urdf.read(MODELS[model], diags)
    assert robot is not None
    robot = annotated(robot)
    first = emitted(robot, tmp_path / "a", diags)
    back = smurf_reader.read(tmp_path / f"a/smurf/{robot.name}.smurf", diags)
    assert back is not None
    second = emitted(back, tmp_path / "b", diags)
    assert first.keys() == second.keys()
    assert [k for k in first if first[k] != second[k]] == []
    # What only SMURF holds came back as it was.
    assert back.motors == robot.motors and back.sensors == robot.sensors
    assert back.poses == robot.poses and back.submechanisms == robot.submechanisms
    assert back.annotations == robot.annotations
    assert back.cut_joints["loop"].origin.xyz == robot.cut_joints["loop"].origin.xyz
    assert back.cut_joints["loop"].constraint_axes == robot.cut_joints["loop"].constraint_axes
    assert back.materials["shiny"] == replace(robot.materials["shiny"], span=back.materials["shiny"].span)
    for name, link in robot.links.items():
        assert [(c.bitmask, c.annotations) for c in back.links[name].collisions] == \
               [(c.bitmask, c.annotations) for c in link.collisions]
        assert [v.annotations for v in back.links[name].visuals] == [v.annotations for v in link.visuals]
        assert back.links[name].annotations == link.annotations
    assert {n: j.annotations for n, j in back.joints.items()} == \
           {n: j.annotations for n, j in robot.joints.items()}


def test_smurf_linking_an_sdf_reads_back(tmp_path: Path, diags: Diags) -> None:
    """The SDF names unnamed shapes (`<link>_collision_1`, …); the SMURF's entries still find
    them by their place."""
    from mpc.backends import sdf
    from mpc.ir.program import SdfExport

    robot = urdf.read(MODELS["talos"], diags)
    assert robot is not None
    robot = annotated(robot)
    sdf.emit(robot, SdfExport(mesh_format="input_type", span=SPAN), tmp_path, diags)
    diags.take("W0500", Severity.WARNING)  # mimic joints, motors, … (SDF cannot hold them)
    smurf.emit(robot, SmurfExport(span=SPAN, model_file="sdf/talos.sdf"), tmp_path, diags)
    back = smurf_reader.read(tmp_path / "smurf/talos.smurf", diags)
    assert back is not None
    assert back.motors == robot.motors and back.poses == robot.poses
    for name, link in robot.links.items():
        assert [(c.bitmask, c.annotations) for c in back.links[name].collisions] == \
               [(c.bitmask, c.annotations) for c in link.collisions]
        assert [v.annotations for v in back.links[name].visuals] == [v.annotations for v in link.visuals]


def test_files_are_yaml_that_phobos_reads(tmp_path: Path, diags: Diags) -> None:
    """Plain YAML 1.1 (PyYAML's safe_load), floats stay floats, Phobos's layout and keys."""
    robot = urdf.read(MODELS["ur5"], diags)
    assert robot is not None
    emitted(annotated(robot), tmp_path, diags)
    folder = tmp_path / "smurf"
    index = yaml.safe_load((folder / "ur5.smurf").read_text())
    assert index == {
        "modelname": "ur5", "description": "round trip", "version": "1.0.0", "additional_files": {},
        "files": ["../urdf/ur5.urdf", "ur5_annotations.yml", "ur5_collisions.yml", "ur5_joints.yml",
                  "ur5_links.yml", "ur5_materials.yml", "ur5_motors.yml", "ur5_poses.yml", "ur5_sensors.yml",
                  "ur5_submechanisms.yml", "ur5_thermal.yml", "ur5_visuals.yml"]}
    for name in index["files"][1:]:
        content = yaml.safe_load((folder / name).read_text())
        assert list(content) == [name[len("ur5_"):-len(".yml")]] or name == "ur5_submechanisms.yml"
    motors = yaml.safe_load((folder / "ur5_motors.yml").read_text())["motors"]
    assert motors[0] == {"name": "elbow_joint_motor", "joint": "elbow_joint", "p": 20.0, "i": 0.001, "d": 0,
                         "type": "position",
                         "maxEffort": 150.0, "maxSpeed": 3.15, "maxValue": 3.14159265359,
                         "minValue": -3.14159265359}
    joints = yaml.safe_load((folder / "ur5_joints.yml").read_text())["joints"]
    loop = next(j for j in joints if j["name"] == "loop")
    assert loop["origin"]["rpy"] == [0.0, 0.25, -1e-05]  # `-1.0e-05`: a float for YAML 1.1 too
    assert "rpy:\n    - 0.0\n    - 0.25\n    - -1.0e-05\n" in (folder / "ur5_joints.yml").read_text()
    collisions = yaml.safe_load((folder / "ur5_collisions.yml").read_text())["collisions"]
    assert {"name": "base_link_collision", "link": "base_link", "bitmask": 0, "ccfm": 0.002} in collisions
    # Every element has its entry, with Phobos's keys.
    links = yaml.safe_load((folder / "ur5_links.yml").read_text())["links"]
    base_link = next(x for x in links if x["name"] == "base_link")
    assert base_link == {"name": "base_link", "collisions": ["base_link_collision"],
                         "visuals": ["base_link_visual"], "index_hint": base_link["index_hint"]}
    assert len(links) == len(robot.links)
    assert {"name": "elbow_joint", "parent": "upper_arm_link", "child": "forearm_link",
            "joint_type": "revolute", "cut_joint": False, "constraint_axes": [], "motor": "elbow_joint_motor",
            "noDataPackage": False} in joints
    materials = yaml.safe_load((folder / "ur5_materials.yml").read_text())["materials"]
    assert {"name": "shiny", "diffuseColor": {"r": 0.0, "g": 0.0, "b": 1.0, "a": 1.0}, "transparency": 0.0,
            "specularColor": {"r": 1.0, "g": 1.0, "b": 1.0}, "shininess": 20.0, "kind": "metal"} in materials
    sensors = yaml.safe_load((folder / "ur5_sensors.yml").read_text())["sensors"]
    assert {"name": "imu", "type": "IMU", "link": "world", "position_offset": {"x": 0.0, "y": 0.0, "z": 0.05},
            "rate": 100} in sensors


# -- from the command line ----------------------------------------------------------------------

UR5 = f"""\
model:
  robotname: ur5
  modelname: ur5-model
  version: 1.2.0
  input_models:
    ur5:
      basefile: {MODELS['ur5']}
  assemble:
    model: ur5
  frames:
    forearm_link: {{colour_hint: grey}}
  joints:
    shoulder_pan_joint:
      active: {{p: 20, i: 0.001, d: 0.1}}
      noDataPackage: false
    elbow_joint:
      motor: {{name: elbow_drive, type: dc}}
  collisions:
    $default:
      ccfm: 0.002
    auto_bitmask: true
  sensors:
    - {{type: IMU, name: wrist_imu, link: wrist_3_link, position_offset: [0, 0, 0.05], rate: 100}}
    - {{type: JointPosition, name: encoders, targets: All}}
  poses:
    home: {{shoulder_lift_joint: -1.57, elbow_joint: 1.57}}
  submechanisms:
    - name: arm
      type: serial
      contextual_name: arm
      jointnames_spanningtree: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint]
      jointnames_independent: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint]
      jointnames_active: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint]
  annotations:
    named_annotations:
      thermal:
        forearm_link: {{max_temperature: 60}}
  export_config:
    - type: urdf
      mesh_format: stl
      link_in_smurf: true
    - type: sdf
"""


def child(kind: str, source: str) -> str:
    return f"""\
model:
  robotname: ur5
  modelname: ur5-{kind}
  version: 1.2.0
  input_models:
    ur5:
      {kind}: {source}
  assemble:
    model: ur5
  export_config:
    - type: urdf
      mesh_format: stl
      link_in_smurf: true
    - type: sdf
"""


def smurf_files(out: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted((out / "smurf").iterdir())}


def test_annotations_survive_derived_base_and_smurf_input(tmp_path: Path) -> None:
    write(tmp_path / "ur5.yml", UR5)
    write(tmp_path / "derived.yml", child("derived_base", "ur5.yml"))
    write(tmp_path / "from_smurf.yml", child("basefile", "out/parent/smurf/ur5.smurf"))
    outs = {}
    for name in ("ur5", "derived", "from_smurf"):
        out = tmp_path / "out" / ("parent" if name == "ur5" else name)
        run = mpc("compile", tmp_path / f"{name}.yml", "-o", out)
        assert run.returncode == 0, run.stderr
        outs[name] = smurf_files(out)
    parent = outs["ur5"]
    assert sorted(parent) == ["ur5.smurf", "ur5_collisions.yml", "ur5_joints.yml", "ur5_links.yml",
                              "ur5_motors.yml", "ur5_poses.yml", "ur5_self_collision.yml", "ur5_sensors.yml",
                              "ur5_submechanisms.yml", "ur5_thermal.yml", "ur5_visuals.yml"]
    index = yaml.safe_load(parent["ur5.smurf"])
    assert index["files"][0] == "../urdf/ur5.urdf"
    assert index["additional_files"] == {"sdf": "../sdf/ur5.sdf"}
    bitmasks = {c["link"]: c["bitmask"] for c in yaml.safe_load(parent["ur5_collisions.yml"])["collisions"]}
    assert len(bitmasks) == 8 and all(bitmasks.values())
    assert bitmasks["upper_arm_link"] & bitmasks["forearm_link"] == 0  # parent and child never collide
    motors = {m["name"]: m for m in yaml.safe_load(parent["ur5_motors.yml"])["motors"]}
    assert motors["shoulder_pan_joint_motor"]["p"] == 20.0 and motors["elbow_drive"]["type"] == "dc"
    submechanisms = yaml.safe_load(parent["ur5_submechanisms.yml"])["submechanisms"]
    assert submechanisms[0]["name"] == "arm"
    assert outs["derived"] == parent
    assert outs["from_smurf"] == parent


# -- diagnostics --------------------------------------------------------------------------------

HEAD = """\
model:
  robotname: arm
  modelname: arm-model
  input_models:
    arm:
      basefile: arm.urdf
  assemble:
    model: arm
  export_config:
"""


def test_link_in_smurf_twice(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + """\
    - {type: urdf, link_in_smurf: true}
    - {type: sdf, link_in_smurf: true}
    - {type: mjcf, link_in_smurf: true}
""")
    run = mpc("check", "--format", "gcc", spec)
    assert run.returncode == 1
    assert run.stderr.splitlines() == [
        f"{spec}:11:19: error: link_in_smurf is set on two exports of the model; a SMURF links one URDF or "
        "SDF file (the others go to its additional_files) [E0510]",
        f"{spec}:12:20: error: a SMURF links a URDF or an SDF file, not mjcf [E0511]",
    ]


def test_second_smurf_entry_warns_and_first_writes(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD + "    - {type: urdf}\n    - {type: smurf}\n    - {type: smurf}\n")
    run = mpc("compile", "--format", "gcc", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    assert f"{spec}:12:14: warning: SMURF is written once per output folder (always, without an entry); " \
           "this entry repeats it [W0510]" in run.stderr
    assert yaml.safe_load((tmp_path / "out/smurf/arm.smurf").read_text())["files"][0] == "../urdf/arm.urdf"


def broken_smurf(tmp_path: Path, motors: str, files: str = "[../arm.urdf, arm_motors.yml]") -> Path:
    arm(tmp_path)
    write(tmp_path / "smurf/arm.smurf", f"modelname: arm\nfiles: {files}\n")
    write(tmp_path / "smurf/arm_motors.yml", motors)
    return write(tmp_path / "m.yml", HEAD.replace("arm.urdf", "smurf/arm.smurf") + "    - {type: urdf}\n")


def test_broken_annotation_points_at_its_line(tmp_path: Path) -> None:
    spec = broken_smurf(tmp_path, "motors:\n  - name: m1\n    joint: shoulder\n"
                                  "  - name: m2\n    joint: elbw\n")
    run = mpc("check", "--format", "gcc", spec)
    assert run.returncode == 1
    assert run.stderr == (f"{tmp_path}/smurf/arm_motors.yml:5:12: error: motors entry 'm2': the model has "
                          "no joint 'elbw'; did you mean 'elbow'? [E0514]\n")


def test_malformed_smurf_files(tmp_path: Path) -> None:
    spec = broken_smurf(tmp_path, "motors:\n  - joint: shoulder\n")
    run = mpc("check", "--format", "gcc", spec)
    assert run.stderr == (f"{tmp_path}/smurf/arm_motors.yml:2:5: error: each entry of 'motors' is a "
                          "mapping with a 'name' [E0512]\n")
    spec = broken_smurf(tmp_path, "motors: []\n", files="[../arm.urdf, ../arm.sdf]")
    run = mpc("check", "--format", "gcc", spec)
    assert run.stderr == (f"{tmp_path}/smurf/arm.smurf:2:22: error: the SMURF lists 2 model files "
                          "(../arm.urdf, ../arm.sdf); it links one, the others belong in 'additional_files' "
                          "[E0513]\n")
    spec = broken_smurf(tmp_path, "motors: [\n")
    run = mpc("check", "--format", "gcc", spec)
    assert run.stderr.startswith(f"{tmp_path}/smurf/arm_motors.yml:2:1: error: malformed YAML")


def test_category_that_is_not_a_file_name(tmp_path: Path) -> None:
    """A category becomes part of a file name; one with a '/' would write outside smurf/."""
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", HEAD.replace("  export_config:\n", """\
  annotations:
    named_annotations:
      ../../escape: {a: 1}
  export_config:
""") + "    - {type: urdf}\n")
    run = mpc("compile", "--format", "gcc", spec, "-o", tmp_path / "out")
    assert run.returncode == 1
    assert run.stderr.splitlines()[0] == (
        f"{spec}:12:3: error: the SMURF cannot write 'arm_../../escape' as file names in smurf/ (the base "
        "name is `filename` or the robot's name, then '_' and each annotation category): no '/' or '\\', "
        "and no '.' first [E0515]")
    assert not (tmp_path / "out").exists() and not list(tmp_path.glob("*escape*"))


def test_renaming_in_a_derived_model_renames_what_the_smurf_names(tmp_path: Path, diags: Diags) -> None:
    """A derived model that prefixes every name: its SMURF names the new links and joints,
    so it reads back without an error."""
    write(tmp_path / "ur5.yml", UR5)
    write(tmp_path / "right.yml", child("derived_base", "ur5.yml").replace(
        "    model: ur5\n", "    model: ur5\n    name_editing: {prefix: r_}\n"))
    run = mpc("compile", tmp_path / "right.yml", "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    robot = smurf_reader.read(tmp_path / "out/smurf/ur5.smurf", diags)
    assert robot is not None
    assert {m.joint for m in robot.motors.values()} == {"r_shoulder_pan_joint", "r_elbow_joint"}
    assert robot.sensors["wrist_imu"].link == "r_wrist_3_link"
    assert robot.sensors["encoders"].targets[0] == "r_shoulder_pan_joint"
    assert robot.poses["home"] == {"r_shoulder_lift_joint": -1.57, "r_elbow_joint": 1.57}
    assert robot.submechanisms[0].definition["jointnames_active"] == [
        "r_shoulder_pan_joint", "r_shoulder_lift_joint", "r_elbow_joint"]
    pairs = robot.annotations["self_collision"]["may_collide"]
    assert pairs and all(n.startswith("r_") for pair in pairs for n in pair)
    assert all(c.bitmask for link in robot.links.values() for c in link.collisions)
