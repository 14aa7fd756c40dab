"""The zero pose of a picture keeps every joint within its limits (issue 29, point 20): a
joint whose limits leave 0 out is drawn at the limit nearest 0, as `mpc view` starts it, and
a warning (the render export) or a note (the test protocol's pictures) says so."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from mpc.checks.pictures import draw
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Severity
from mpc.ir.program import Tolerances
from tests.conftest import Diags, write

ARM = """<robot name="arm">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="upper"><visual><origin xyz="0 0 0.25"/>
    <geometry><box size="0.05 0.05 0.5"/></geometry></visual></link>
  <link name="lower"><visual><origin xyz="0 0 0.2"/>
    <geometry><box size="0.04 0.04 0.4"/></geometry></visual></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0 0 0.5"/>
    <axis xyz="0 1 0"/><limit lower="0.8" upper="2" effort="1" velocity="1"/></joint>
</robot>
"""
NOTE = ("1 joint of robot 'arm' cannot be at 0 within its limits and is drawn at the limit nearest 0: "
        "'elbow' at 0.8")


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


def compiled(tmp_path: Path, diags: Diags, poses: str = "") -> Path:
    write(tmp_path / "arm.urdf", ARM)
    path = write(tmp_path / "arm.yml", textwrap.dedent("""\
        model:
          robotname: arm
          modelname: arm
          input_models: {base: {basefile: arm.urdf}}
          assemble: {model: base}
          export_config:
            - type: render
              views: side
              size: [96, 96]
              poses: all
        """) + poses)
    result = compile_model(path, diags, Options(out=tmp_path / "out"))
    assert result.out is not None, [d.message for d in diags.diagnostics]
    return tmp_path / "out" / "render"


def test_the_zero_pose_is_drawn_within_the_limits_with_a_warning(tmp_path: Path, diags: Diags) -> None:
    folder = compiled(tmp_path, diags, "  poses:\n    at_limit: {elbow: 0.8}\n    at_zero: {shoulder: 0}\n")
    d = diags.take("W0590", Severity.WARNING)
    assert d.message == NOTE
    assert (d.span.line, d.span.col) == (7, 7)  # the render entry
    zero = (folder / "zero_side.png").read_bytes()
    assert zero == (folder / "at_limit_side.png").read_bytes()  # the elbow at 0.8, not at 0
    assert (folder / "at_zero_side.png").read_bytes() == zero  # a pose that leaves the elbow out


def test_the_protocols_pictures_note_the_joints_drawn_at_a_limit(tmp_path: Path, diags: Diags) -> None:
    compiled(tmp_path, diags)
    diags.take("W0590", Severity.WARNING)
    from mpc.backends.urdf_reader import read

    robot = read(tmp_path / "arm.urdf", diags)
    assert robot is not None
    diff = draw(robot, robot, Tolerances(), None, diags)
    assert diff.problem == "" and diff.drawn
    assert diff.notes == [f"The release model: {NOTE}.", f"The new model: {NOTE}."]
