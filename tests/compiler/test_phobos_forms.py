"""Nine definition forms that Phobos builds (issue 29, point 9): none is an error in mpc. Each is
accepted with its Phobos meaning (checked in the output), or with a warning that says what
mpc does instead; `mpc check` and `mpc compile` say the same."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from mpc.cli.check import check_file
from mpc.compiler.options import Options
from mpc.core.diagnostics import Severity
from tests.conftest import Diags, compile_file, write

URDF = """\
<robot name="r">
  <link name="a"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="b"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="c"/>
</robot>
"""


def _build(tmp_path: Path, section: str, export: str = "", modelname: str = "r_model",
           said: tuple[str, str, str] | None = None) -> Path:
    """Check and compile a definition with `section` in its model and `export` among its
    exports; `said`: the one warning (code, line:col, message) both must say. The output."""
    write(tmp_path / "r.urdf", URDF)
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: r
          modelname: {modelname}
          input_models: {{base: {{basefile: r.urdf}}}}
          assemble: {{model: base}}
        {section}
          export_config:
            - {{type: urdf}}
        {export}
        """)
    checked, compiled = Diags(), Diags()
    check_file(spec, checked, Options())
    out = compile_file(spec, tmp_path / "out", compiled).out
    for sink in (checked, compiled):
        if said is not None:
            code, where, message = said
            warning = sink.take(code, Severity.WARNING)
            assert (f"{warning.span.line}:{warning.span.col}", warning.message) == (where, message)
        assert not sink.diagnostics, sink.summary()
    assert out is not None
    return out


def _smurf(out: Path, category: str) -> object:
    return yaml.safe_load((out / f"smurf/r_{category}.yml").read_text())[category]


def test_provide_primitives_on_an_sdf_export(tmp_path: Path) -> None:
    out = _build(tmp_path, "", "    - {type: sdf, provide_primitives: true}", said=(
        "W0260", "9:19", "'provide_primitives' has no effect: Phobos's export reads it from no export "
        "entry (its default preset sets it on sdf), and mpc writes the collisions as they are"))
    assert (out / "sdf/r.sdf").is_file()


def test_a_section_level_number_for_poses_default(tmp_path: Path) -> None:
    """Phobos: every pose's value of the movable joints it does not list."""
    out = _build(tmp_path, """
          poses:
            $default: 0.5
            home: {j1: 0.2}
            own: {$default: -0.5}
        """)
    assert _smurf(out, "poses") == [{"name": "home", "joints": {"j1": 0.2, "j2": 0.5}},
                                    {"name": "own", "joints": {"j1": -0.5, "j2": -0.5}}]


def test_general_annotations_as_a_list_of_pairs(tmp_path: Path) -> None:
    """Phobos: each pair is a category of its own; mpc merges a category given twice."""
    out = _build(tmp_path, """
          annotations:
            general_annotations:
              - [thermal, {max: 60}]
              - [thermal, {min: 5}]
              - [maintainer, team]
        """, said=("W0262", "11:9", "general_annotations: the content of 'maintainer' is no mapping; mpc "
                   "writes it in the category 'annotations' as 'maintainer' (Phobos writes it to its own "
                   "file, <robot>_maintainer.yml)"))
    assert _smurf(out, "thermal") == {"max": 60, "min": 5}
    assert _smurf(out, "annotations") == {"maintainer": "team"}


def test_collisions_default_without_a_dollar(tmp_path: Path) -> None:
    """Phobos hands `default` to its auto_bitmask, which ignores it: nothing changes."""
    out = _build(tmp_path, """
          collisions:
            default: {bitmask: 3}
        """, said=("W0263", "8:5", "collisions: 'default' names no link or collision, so the entry has no "
                   "effect (Phobos hands it to its auto_bitmask, which ignores it); '$default' edits every "
                   "link's collisions"))
    assert "bitmask" not in (out / "smurf/r_collisions.yml").read_text()


def test_export_total_submechanisms(tmp_path: Path) -> None:
    _build(tmp_path, "  export_total_submechanisms: all_of_them", said=(
        "W0264", "6:3", "'export_total_submechanisms' has no effect: Phobos's code for it (one submodel "
        "of all submechanisms) is commented out"))


@pytest.mark.parametrize("word", ["ALL", "all"])
def test_sensor_targets_all_in_any_case(tmp_path: Path, word: str) -> None:
    out = _build(tmp_path, f"""
          sensors:
            JointPosition: {{name: jp, targets: {word}}}
        """)
    assert _smurf(out, "sensors") == [{"name": "jp", "type": "JointPosition", "targets": ["j1", "j2"]}]


def test_a_multi_link_sensor_without_targets(tmp_path: Path) -> None:
    out = _build(tmp_path, """
          sensors:
            JointPosition: {name: jp}
        """, said=("W0265", "8:5", "JointPosition sensor 'jp' has no 'targets': it measures nothing "
                   "(Phobos gives it an empty list of targets)"))
    assert _smurf(out, "sensors") == [{"name": "jp", "type": "JointPosition"}]


def test_around_human_on_an_exoskeleton(tmp_path: Path) -> None:
    out = _build(tmp_path, """
          exoskeletons:
            - {name: exo, jointnames: [j1], jointnames_spanningtree: [j1], around: human}
        """)
    exoskeletons = yaml.safe_load((out / "smurf/r_submechanisms.yml").read_text())["exoskeletons"]
    assert exoskeletons == [{"name": "exo", "around": "human", "jointnames": ["j1"],
                             "jointnames_spanningtree": ["j1"]}]


def test_ros_pathes_with_a_modelname_that_is_no_ros_package_name(tmp_path: Path) -> None:
    out = _build(tmp_path, "", "    - {type: sdf, ros_pathes: true}", modelname="My Model-1", said=(
        "W0261", "3:14", "modelname 'My Model-1' is not a ROS package name (REP 144: lower-case letters, "
        "digits and '_', starting with a letter); the ROS package that ros_pathes makes is named "
        "'my_model_1' (Phobos keeps the modelname, which no ROS tool finds)"))
    assert "<name>my_model_1</name>" in (out / "package.xml").read_text()
