"""`mpc diff`: pairs of models that differ in known ways list exactly those changes; an
unchanged model, in another format too, lists none and exits 0; a definition at a git revision
is compiled and compared; the Markdown and JSON forms are exact."""

from __future__ import annotations

import json
from pathlib import Path

import git
import pytest
import trimesh

from mpc.checks.diff_change import Change
from mpc.ir.robot import Robot
from tests.conftest import ERD, write
from tests.mpc_command import mpc

ARM = """\
<?xml version="1.0"?>
<robot name="arm">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0.05"/><mass value="4"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></visual>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.15"/><mass value="MASS"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
    <visual><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.04" length="0.3"/></geometry></visual>
    <collision><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.04" length="0.3"/></geometry></collision>
  </link>
  <link name="LOWER">
    <inertial><origin xyz="0 0 0.1"/><mass value="1"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.001"/></inertial>
    <visual><geometry><mesh filename="ball.stl"/></geometry><material name="grey"/></visual>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
  </link>
  <link name="tool"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-LIMIT" upper="LIMIT" effort="50" velocity="2"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="LOWER"/><origin xyz="0 0 ELBOW"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="30" velocity="3"/>
  </joint>
  <joint name="tool_joint" type="fixed">
    <parent link="LOWER"/><child link="tool"/><origin xyz="0 0 0.2"/>
  </joint>
</robot>
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


def arm(folder: Path, mass: str = "2", limit: str = "2.5", elbow: str = "0.3", lower: str = "lower",
        subdivisions: int = 3, elbow_name: str = "elbow") -> Path:
    """The arm URDF (and its mesh) in `folder`, with what the arguments change."""
    folder.mkdir(parents=True, exist_ok=True)
    trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.05).export(folder / "ball.stl")
    text = ARM.replace("MASS", mass).replace("LIMIT", limit).replace("ELBOW", elbow)
    text = text.replace('joint name="elbow"', f'joint name="{elbow_name}"')
    return write(folder / "arm.urdf", text.replace("LOWER", lower))


def changes(old: Path | str, new: Path | str, *args: str, cwd: Path | None = None) -> tuple[int, list[str]]:
    run = mpc("diff", old, new, *args, cwd=cwd)
    assert run.returncode in (0, 1), run.stderr
    return run.returncode, run.stdout.splitlines()[1:]


@pytest.mark.parametrize(("edit", "expected"), [
    ({"limit": "1.0"}, ["joint 'shoulder': limit lower -2.5 → -1, upper 2.5 → 1"]),
    ({"mass": "2.5"}, ["link 'upper': mass 2 → 2.5 kg (+0.5)", "total mass 7 → 7.5 kg (+0.5)",
                       "centre of mass moved by 0.005238 m at the zero pose"]),
    ({"lower": "forearm"}, ["link 'lower' renamed to 'forearm'"]),
    ({"lower": "forearm", "elbow": "0.35"}, ["link 'lower' renamed to 'forearm'",
                                            "joint 'elbow': origin moved by 0.05 m, turned by 0 rad",
                                            "centre of mass moved by 0.007143 m at the zero pose",
                                            "reach at the zero pose 0.6 → 0.65 m"]),
    ({"lower": "forearm", "elbow_name": "knee"}, ["link 'lower' renamed to 'forearm'",
                                                 "joint 'elbow' renamed to 'knee'"]),
    ({"elbow": "0.35"}, ["joint 'elbow': origin moved by 0.05 m, turned by 0 rad",
                         "centre of mass moved by 0.007143 m at the zero pose",
                         "reach at the zero pose 0.6 → 0.65 m"]),
    ({"subdivisions": 2}, ["visual 0: mesh ball.stl: its content changed (1280 → 320 faces, "
                           "64084 → 16084 bytes)"]),
])
def test_a_known_change_is_listed_and_nothing_else(tmp_path: Path, edit: dict, expected: list[str]) -> None:
    old = arm(tmp_path / "old")
    new = arm(tmp_path / "new", **edit)
    code, lines = changes(old, new)
    assert [ln.strip() for ln in lines] == expected
    assert code == 1


@pytest.mark.parametrize(("before", "after", "expected"), [
    ('<axis xyz="0 1 0"/>\n    <limit lower="-LIMIT"', '<axis xyz="1 0 0"/>\n    <limit lower="-LIMIT"',
     ["joint 'shoulder': axis (0 1 0) → (1 0 0)"]),
    ('<parent link="upper"/>', '<parent link="upper"/><dynamics damping="0.5"/>',
     ["joint 'elbow': dynamics damping none → 0.5"]),
    ('<box size="0.05 0.05 0.2"/>', '<box size="0.05 0.05 0.3"/>',
     ["collision 0: box 0.05×0.05×0.2 → box 0.05×0.05×0.3 (0.0005 → 0.00075 m³)"]),
    ('<color rgba="0.5 0.5 0.5 1"/>', '<color rgba="0.9 0.1 0.1 1"/>',
     ["visual 0: material rgba 0.5 0.5 0.5 1 → rgba 0.9 0.1 0.1 1"]),
    ('ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"', 'ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
     'iyz="0" izz="0.01"', ["link 'upper': principal moments of inertia 0.002, 0.01, 0.01 → 0.01, 0.01, "
                            "0.01 kg·m²"]),
    ('ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"', 'ixx="0.002" ixy="0" ixz="0" iyy="0.01" '
     'iyz="0" izz="0.01"', ["link 'upper': principal axes of inertia turned by 1.571 rad"]),
])
def test_a_changed_property_is_listed(tmp_path: Path, before: str, after: str, expected: list[str]) -> None:
    old = arm(tmp_path / "old")
    new = arm(tmp_path / "new")
    text = ARM.replace("LIMIT", "2.5").replace(before.replace("LIMIT", "2.5"), after.replace("LIMIT", "2.5"))
    assert text != ARM.replace("LIMIT", "2.5")
    write(new, text.replace("MASS", "2").replace("ELBOW", "0.3").replace("LOWER", "lower"))
    code, lines = changes(old, new)
    assert ([ln.strip() for ln in lines], code) == (expected, 1)


def test_the_unchanged_model_exits_0_in_any_format_it_is_written_in(tmp_path: Path) -> None:
    source = arm(tmp_path / "in")
    write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm
          input_models:
            base:
              basefile: "{source}"
          assemble:
            model: base
          export_config:
            - type: urdf
            - type: sdf
            - type: smurf
        """)
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "out").returncode == 0
    for other in ("sdf/arm.sdf", "smurf/arm.smurf", "", "../m.yml"):
        run = mpc("diff", source, tmp_path / "out" / other)
        assert (run.returncode, run.stderr) == (0, ""), run.stdout
        assert run.stdout.endswith(": no changes beyond the tolerances (mass 0.01 kg, distance 0.003 m, "
                                   "angle 0.03 rad, other 0.01)\n")


def test_thresholds_are_options(tmp_path: Path) -> None:
    old, new = arm(tmp_path / "old"), arm(tmp_path / "new", mass="2.005")
    assert mpc("diff", old, new).returncode == 0  # within mpc test's 0.01 kg
    run = mpc("diff", old, new, "--mass", "0.001")
    assert run.returncode == 1
    assert "link 'upper': mass 2 → 2.005 kg (+0.005)" in run.stdout


def test_an_added_sensor_between_definitions(tmp_path: Path) -> None:
    source = arm(tmp_path / "in")
    base = f"""
        model:
          robotname: arm
          modelname: arm
          input_models:
            base:
              basefile: "{source}"
          assemble:
            model: base
          export_config:
            - type: urdf
            - type: smurf
        """
    write(tmp_path / "a.yml", base)
    sensor = "          sensors:\n            - {type: IMU, name: imu, link: upper}\n"
    write(tmp_path / "b.yml", base.rstrip(" ") + sensor)
    code, lines = changes(tmp_path / "a.yml", tmp_path / "b.yml")
    assert (code, lines) == (1, ["  sensor 'imu' added (IMU on link 'upper')"])


def test_poses_and_renamed_links_in_annotations(tmp_path: Path) -> None:
    """A pose's value changed beyond `rad` is listed; a sensor on a renamed link is not."""
    base = f"""
        model:
          robotname: arm
          modelname: arm
          input_models:
            base:
              basefile: "{arm(tmp_path / "old")}"
          assemble:
            model: base
          export_config:
            - type: urdf
            - type: smurf
          sensors:
            - {{type: IMU, name: imu, link: LINK}}
          poses:
            init:
              shoulder: SHOULDER
        """
    write(tmp_path / "a.yml", base.replace("LINK", "lower").replace("SHOULDER", "0.5"))
    arm(tmp_path / "new", lower="forearm")
    write(tmp_path / "b.yml", base.replace("LINK", "forearm").replace("SHOULDER", "0.52").replace(
        "old/arm.urdf", "new/arm.urdf"))
    assert changes(tmp_path / "a.yml", tmp_path / "b.yml") == (1, ["  link 'lower' renamed to 'forearm'"])
    write(tmp_path / "c.yml", base.replace("LINK", "forearm").replace("SHOULDER", "0.6").replace(
        "old/arm.urdf", "new/arm.urdf"))
    assert changes(tmp_path / "a.yml", tmp_path / "c.yml") == (1, [
        "  link 'lower' renamed to 'forearm'", "  pose 'init': shoulder: 0.5 → 0.6"])


def test_markdown_and_json_are_exact(tmp_path: Path) -> None:
    arm(tmp_path / "old"), arm(tmp_path / "new", limit="1.0")
    run = mpc("diff", "old/arm.urdf", "new/arm.urdf", "--format", "markdown", cwd=tmp_path)
    assert run.returncode == 1
    assert run.stdout == (
        "## Model diff: `old/arm.urdf` → `new/arm.urdf`\n\n"
        "**1 change** beyond the tolerances (mass 0.01 kg, distance 0.003 m, angle 0.03 rad, other 0.01).\n\n"
        "- joint `shoulder`: limit lower -2.5 → -1, upper 2.5 → 1\n")
    run = mpc("diff", "old/arm.urdf", "new/arm.urdf", "--format", "json", cwd=tmp_path)
    assert run.returncode == 1
    assert json.loads(run.stdout) == {
        "old": "old/arm.urdf", "new": "new/arm.urdf", "changed": True,
        "tolerances": {"mass": 0.01, "distance": 0.003, "rad": 0.03, "default": 0.01},
        "changes": [{"element": "joint", "name": "shoulder", "aspect": "limit",
                     "old": {"lower": -2.5, "upper": 2.5, "effort": 50.0, "velocity": 2.0},
                     "new": {"lower": -1.0, "upper": 1.0, "effort": 50.0, "velocity": 2.0},
                     "text": "joint 'shoulder': limit lower -2.5 → -1, upper 2.5 → 1"}],
        "pictures": []}


def test_a_definition_at_the_last_commit(tmp_path: Path) -> None:
    repo = git.Repo.init(tmp_path / "repo", initial_branch="main")
    arm(tmp_path / "repo/model")
    write(tmp_path / "repo/model.yml", """
        model:
          robotname: arm
          modelname: arm
          input_models:
            base:
              basefile: model/arm.urdf
          assemble:
            model: base
          export_config:
            - type: urdf
        """)
    repo.index.add(["model.yml", "model/arm.urdf", "model/ball.stl"])
    repo.index.commit("the arm", author=git.Actor("a", "a@b"), committer=git.Actor("a", "a@b"))
    arm(tmp_path / "repo/model", limit="1.0")
    repo.index.add(["model/arm.urdf"])
    repo.index.commit("narrower", author=git.Actor("a", "a@b"), committer=git.Actor("a", "a@b"))
    arm(tmp_path / "repo/model", limit="1.0", mass="3")  # not committed
    code, lines = changes("model.yml@HEAD~1", "model.yml", cwd=tmp_path / "repo")
    assert (code, lines) == (1, ["  link 'upper': mass 2 → 3 kg (+1)",
                                 "  joint 'shoulder': limit lower -2.5 → -1, upper 2.5 → 1",
                                 "  total mass 7 → 8 kg (+1)",
                                 "  centre of mass moved by 0.009821 m at the zero pose"])
    assert mpc("diff", "model.yml@HEAD", "model/arm.urdf@HEAD", cwd=tmp_path / "repo").returncode == 0
    assert mpc("diff", "model.yml@HEAD~1", "model.yml@HEAD~1", cwd=tmp_path / "repo").returncode == 0


@pytest.mark.parametrize(("args", "message"), [
    (("nowhere.urdf", "a/arm.urdf"), "mpc diff: error: 'nowhere.urdf' does not exist\n"),
    (("a/arm.urdf@HEAD", "a/arm.urdf"), "a/arm.urdf:1:1: error[E0741]: 'a/arm.urdf' is not in a git work "
     "tree: fatal: not a git repository (or any of the parent directories): .git\n"),
    (("a", "a/arm.urdf"),
     "a:1:1: error[E0740]: no model file (urdf/*.urdf, *.urdf, sdf/*.sdf) in folder 'a'"),
    (("arm.xml", "a/arm.urdf"),
     "arm.xml:2:34: error[E0440]: MuJoCo refuses 'arm.xml': attribute 'range' does not have enough data\n"),
    (("bad.urdf", "a/arm.urdf"), "bad.urdf:3:9: error[E0401]: malformed XML in 'bad.urdf': Opening and "
     "ending tag mismatch: link line 2 and robot\n"),
])
def test_bad_input_says_where_and_exits_2(tmp_path: Path, args: tuple[str, str], message: str) -> None:
    arm(tmp_path / "a")
    write(tmp_path / "bad.urdf", '<robot name="x">\n  <link name="a">\n</robot>\n')
    write(tmp_path / "arm.xml",
          '<mujoco model="arm">\n  <worldbody><body><joint range="1"/></body></worldbody>\n</mujoco>\n')
    if args[0] == "a":  # a folder without a model file
        (tmp_path / "a/arm.urdf").rename(tmp_path / "arm.urdf")
        args = ("a", "arm.urdf")
    run = mpc("diff", *args, cwd=tmp_path)
    assert run.returncode == 2
    assert run.stdout == ""
    assert run.stderr.startswith(message)


def _in_mjcf_form(change: Change, urdf: Robot) -> bool:
    """What an MJCF holds in another form than the URDF, as mpc reads it back (specs/exports.md,
    "Read back"): a DAE visual split per material with its colours, a fixed joint as a welded
    body (read back as `<child>_fixed`), a massless root link as MuJoCo's world body."""
    root_joints = {j.name for j in urdf.joints.values() if j.parent == urdf.root}
    fixed = change.aspect == "renamed" and change.name.endswith("_fixed")
    return change.text.startswith("visual ") or fixed or (
        change.aspect == "removed" and change.name in {urdf.root, *root_joints})


@pytest.mark.parametrize("robot", ["panda_description/urdf/panda.urdf", "ur_description/urdf/ur5_robot.urdf"])
def test_a_urdf_against_its_own_exports_shows_only_documented_losses(tmp_path: Path, robot: str) -> None:
    from mpc.backends.formats import FORMATS
    from mpc.backends.holds import left_out
    from mpc.checks.diff_models import diff
    from mpc.checks.models import read_model
    from mpc.core.diagnostics import Sink

    name = Path(robot).stem
    write(tmp_path / "m.yml", f"""
        model:
          robotname: {name}
          modelname: {name}
          input_models:
            base:
              basefile: "{ERD / robot}"
          assemble:
            model: base
          export_config:
            - {{type: urdf, mesh_format: obj}}
            - {{type: sdf, mesh_format: obj}}
            - type: smurf
            - type: mjcf
        """)
    assert mpc("compile", tmp_path / "m.yml", "-o", tmp_path / "out").returncode == 0
    urdf = read_model(tmp_path / f"out/urdf/{name}.urdf", Sink())
    assert urdf is not None
    files = {"sdf": f"sdf/{name}.sdf", "smurf": f"smurf/{name}.smurf", "mjcf": f"mjcf/{name}.xml"}
    for fmt in files:
        other = read_model(tmp_path / "out" / files[fmt], Sink())
        assert other is not None
        holds = FORMATS[fmt].holds
        losses = left_out(urdf, holds(), cut_joints=False) if holds is not None else []
        for change in diff(urdf, other).changes:  # each one a loss the format's table names
            if fmt == "mjcf" and _in_mjcf_form(change, urdf):
                continue
            assert any(change.aspect in phrase and (f"'{change.name}'" in phrase or phrase[0].isdigit())
                       for phrase in losses), (fmt, change.text, losses)
    run = mpc("diff", tmp_path / f"out/urdf/{name}.urdf", tmp_path / f"out/sdf/{name}.sdf")
    mimics = [j for j in ("panda_finger_joint2",) if name == "panda"]
    assert run.returncode == int(bool(mimics))
    assert run.stdout.splitlines()[1:] == [f"  joint '{j}': mimic panda_finger_joint1 ×1 +0 → none"
                                           for j in mimics]


@pytest.mark.parametrize("args", [("a.urdf",), ("a.urdf", "a.urdf", "--mass", "-1"),
                                  ("a.urdf", "a.urdf", "--format", "gcc"),
                                  ("a.urdf", "a.urdf", "--rad", "x")])
def test_a_bad_command_line_exits_2(tmp_path: Path, args: tuple[str, ...]) -> None:
    arm(tmp_path).rename(tmp_path / "a.urdf")
    run = mpc("diff", *args, cwd=tmp_path)
    assert (run.returncode, run.stdout) == (2, "")
    assert run.stderr.startswith("usage: mpc diff")
