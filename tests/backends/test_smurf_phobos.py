"""SMURF as Phobos writes it: a release in Phobos's layout (tests/phobos_release.py) compiles
as a `basefile`, every annotation survives into mpc's SMURF in Phobos's value forms, and
reading and writing again gives the same files, from the command line and in-process."""

from __future__ import annotations

import json
from pathlib import Path

import yaml

from mpc.backends import smurf, smurf_reader, urdf
from mpc.core.span import Span
from mpc.ir.program import SmurfExport, UrdfExport
from tests.conftest import Diags, write
from tests.mpc_command import mpc
from tests.phobos_release import ANNOTATIONS, SUBMECHANISMS, write_release

DEFINITION = """\
model:
  robotname: fourbar
  modelname: fourbar-model
  input_models: {{base: {{basefile: {basefile}}}}}
  assemble: {{model: base}}
  export_config:
    - {{type: urdf, mesh_format: input_type, link_in_smurf: true}}
    - {{type: joint_limits}}
"""


def compiled(tmp_path: Path, basefile: str, out: str) -> dict[str, str]:
    spec = write(tmp_path / f"{out}.yml", DEFINITION.format(basefile=basefile))
    done = mpc("compile", spec, "-o", tmp_path / out)
    assert done.returncode == 0, done.stderr
    assert done.stderr == "", done.stderr  # no warning either
    return {p.name: p.read_text() for p in sorted((tmp_path / out / "smurf").iterdir())}


def entries(files: dict[str, str], category: str) -> dict[str, dict]:
    return {e["name"]: e for e in yaml.safe_load(files[f"fourbar_{category}.yml"])[category]}


def test_a_phobos_smurf_compiles_and_every_annotation_survives(tmp_path: Path) -> None:
    write_release(tmp_path / "release")
    files = compiled(tmp_path, "release/smurf/fourbar.smurf", "out")
    # The same set of files as Phobos, each with every entry of its category.
    categories = (*ANNOTATIONS, "submechanisms")
    assert sorted(files) == ["fourbar.smurf", *sorted(f"fourbar_{c}.yml" for c in categories)]
    index = yaml.safe_load(files["fourbar.smurf"])
    assert index["files"] == ["../urdf/fourbar.urdf", *sorted(f for f in files if f.endswith(".yml"))]
    assert index["additional_files"] == {}
    for category in ANNOTATIONS:
        assert entries(files, category).keys() == {e["name"] for e in ANNOTATIONS[category]}, category
    # Collisions listed by name only: found through the URDF.
    collisions = entries(files, "collisions")
    assert collisions["base_collision"] == {"name": "base_collision", "link": "base", "noDataPackage": False,
                                            "reducedDataPackage": False}
    coupler = collisions["coupler_collision"]
    assert (coupler["bitmask"], coupler["link"]) == (5, "coupler")
    # Colours given as lists come out as Phobos 2.x's mappings, values unchanged.
    grey = entries(files, "materials")["grey"]
    assert grey["diffuseColor"] == {"r": 0.5, "g": 0.5, "b": 0.5, "a": 1.0}
    assert grey["specularColor"]["r"] == 0.4980392156862745 and grey["shininess"] == 40.0
    assert entries(files, "materials")["orange"]["emissionColor"] == {"r": 0.1, "g": 0.05, "b": 0.0, "a": 1.0}
    # The camera: offsets as {x, y, z} and a quaternion, every key mpc does not model kept.
    camera = entries(files, "sensors")["camera_on_rocker"]
    assert camera == ANNOTATIONS["sensors"][0]
    # Free keys on links and joints, the loop-closure joint, the motor, the pose, the submechanism.
    assert entries(files, "links")["rocker"] == ANNOTATIONS["links"][4]
    assert entries(files, "joints")["coupler_joint"] == ANNOTATIONS["joints"][1]
    loop = entries(files, "joints")["loop"]
    assert (loop["cut_joint"], loop["parent"], loop["child"]) == (True, "coupler_tip", "rocker_tip")
    assert loop["constraint_axes"] == [{"name": "y", "axis": [0.0, 1.0, 0.0]}]
    assert entries(files, "motors")["crank_motor"] == ANNOTATIONS["motors"][0]
    assert entries(files, "poses")["tilted"] == ANNOTATIONS["poses"][0]
    assert yaml.safe_load(files["fourbar_submechanisms.yml"]) == SUBMECHANISMS
    # Every key Phobos wrote is there, with the same value (mpc adds the keys it always writes).
    for category, listed in ANNOTATIONS.items():
        written = entries(files, category)
        for entry in listed:
            keys = set(entry) - {"origin"}  # a cut joint's origin: xyz/rpy instead of position/rotation
            assert {k: written[entry["name"]].get(k) for k in keys} == {k: entry[k] for k in keys} or \
                category == "materials", (category, entry["name"])


def test_read_write_read_is_stable_for_phobos_files_and_for_mpcs(tmp_path: Path, diags: Diags) -> None:
    """Compiling mpc's output again gives the same bytes; so does reading and writing the
    Phobos release in-process, twice."""
    write_release(tmp_path / "release")
    first = compiled(tmp_path, "release/smurf/fourbar.smurf", "out")
    again = compiled(tmp_path, "out/smurf/fourbar.smurf", "again")
    assert again == first
    span = Span("test", 1, 1)
    outputs = []
    source = tmp_path / "release/smurf/fourbar.smurf"
    for i in range(3):
        robot = smurf_reader.read(source, diags)
        assert robot is not None
        out = tmp_path / f"round{i}"
        urdf.emit(robot, UrdfExport(mesh_format="input_type", span=span), out, diags)
        smurf.emit(robot, SmurfExport(span=span, model_file="urdf/fourbar.urdf"), out, diags)
        outputs.append({p.name: p.read_bytes() for p in sorted((out / "smurf").iterdir())})
        source = out / "smurf/fourbar.smurf"
    assert outputs[0] == outputs[1] == outputs[2]


def test_phobos_value_forms_that_are_wrong_point_at_their_line(tmp_path: Path) -> None:
    """A colour of 2 numbers, an offset mapping without z, a collision no link has: located errors."""
    smurf_file = write_release(tmp_path / "release")
    materials = smurf_file.parent / "fourbar_materials.yml"
    data = json.loads(materials.read_text())
    data["materials"][0]["diffuseColor"] = [0.5, 0.5]
    materials.write_text(json.dumps(data, indent=2))
    sensors = smurf_file.parent / "fourbar_sensors.yml"
    data = json.loads(sensors.read_text())
    data["sensors"][0]["position_offset"] = {"x": 0.0, "y": 0.1}
    sensors.write_text(json.dumps(data, indent=2, sort_keys=True))
    collisions = smurf_file.parent / "fourbar_collisions.yml"
    data = json.loads(collisions.read_text())
    data["collisions"][0]["name"] = "base_colision"
    collisions.write_text(json.dumps(data, indent=2, sort_keys=True))
    spec = write(tmp_path / "m.yml", DEFINITION.format(basefile="release/smurf/fourbar.smurf"))
    done = mpc("check", spec)
    assert done.returncode == 1
    assert f"{materials}:10:23: error[E0512]: 'diffuseColor' of material 'grey' is r, g, b, a: numbers, " \
           "as a mapping or a list" in done.stderr, done.stderr
    assert f"{sensors}:19:26: error[E0512]: 'position_offset' of sensor 'camera_on_rocker' is 3 numbers or " \
           "a mapping x, y, z" in done.stderr, done.stderr
    assert f"{collisions}:4:15: error[E0514]: collisions entry 'base_colision' names no collision in the " \
           "model" in done.stderr, done.stderr
