"""A motor's maxEffort and maxSpeed are its joint's limits too (issue 29, point 10): one value
for both, in the URDF and the SMURF, with W0504 where they were given differently."""

from __future__ import annotations

from pathlib import Path

import yaml
from lxml import etree

from mpc.core.diagnostics import Severity
from tests.conftest import Diags, compile_file, write

URDF = """\
<robot name="robot">
  <link name="a"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="30" velocity="2"/></joint>
  <link name="b"/>
</robot>
"""


def _compile(tmp_path: Path, diags: Diags, motor: str) -> tuple[dict[str, str], dict[str, object]]:
    write(tmp_path / "r.urdf", URDF)
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: robot
          modelname: robot_model
          input_models: {{base: {{basefile: r.urdf}}}}
          assemble: {{model: base}}
          joints:
            j: {{active: {motor}}}
          export_config:
            - {{type: urdf}}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    limit = etree.parse(str(out / "urdf/robot.urdf")).getroot().find("joint/limit")
    motors = yaml.safe_load((out / "smurf/robot_motors.yml").read_text())["motors"]
    return dict(limit.attrib), motors[0]


def test_a_motor_limit_given_differently_wins_with_a_warning(tmp_path: Path, diags: Diags) -> None:
    limit, motor = _compile(tmp_path, diags, "{maxEffort: 50, maxSpeed: 2}")
    warning = diags.take("W0504", Severity.WARNING)
    assert warning.message == ("the motor 'j_motor' of joint 'j' has maxEffort 50, its joint's limit effort "
                               "is 30: both are now 50, the motor's (Phobos reads a motor's from its joint)")
    assert (warning.span.line, warning.span.col) == (7, 9)  # `active`
    assert (float(limit["effort"]), float(limit["velocity"])) == (50, 2)
    assert (motor["maxEffort"], motor["maxSpeed"]) == (50, 2)


def test_a_motor_without_limits_takes_its_joints(tmp_path: Path, diags: Diags) -> None:
    limit, motor = _compile(tmp_path, diags, "{p: 1}")
    assert (float(limit["effort"]), float(limit["velocity"])) == (30, 2)
    assert (motor["maxEffort"], motor["maxSpeed"]) == (30, 2)
