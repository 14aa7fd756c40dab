"""Exports hold their consumers' rules of physical validity (issue 29, point 5): an SDF export
refuses an inertial SDFormat refuses, or corrects it with `correct_inertials`; `mpc check`
reports what compiling would refuse (E0504, E0505)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from mpc.cli.check import check_file
from mpc.compiler.options import Options
from mpc.core.diagnostics import Severity
from tests.conftest import Diags, compile_file, write

IGN = shutil.which("ign")

# link 'flat': principal moments 0.1, 0.1, 0.5 (0.1 + 0.1 < 0.5), which SDFormat refuses.
URDF = """\
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="flat"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="flat">
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.5"/></inertial>
  </link>
  <joint name="floating_base" type="fixed"><parent link="base"/><child link="trunk"/></joint>
  <link name="trunk"/>
</robot>
"""


def _definition(tmp_path: Path, export: str) -> Path:
    write(tmp_path / "r.urdf", URDF)
    return write(tmp_path / "m.yml", f"""
        model:
          robotname: r
          modelname: r_model
          input_models: {{base: {{basefile: r.urdf}}}}
          assemble: {{model: base}}
          export_config:
            - {export}
        """)


def _take_refusal(diags: Diags, tmp_path: Path) -> None:
    error = diags.take_error("E0504")
    assert error.message == ("link 'flat' has an inertial SDFormat refuses: its principal moments "
                             "violate A + B ≥ C (0.1 + 0.1 < 0.5)")
    assert (Path(error.span.file).name, error.span.line, error.span.col) == ("r.urdf", 7, 3)
    assert error.hint == ("set `correct_inertials: true` on the export to make it physical, or fix its "
                          "inertial")
    assert [(Path(s.file).name, s.line, s.col, text) for s, text in error.notes if s] == [
        ("m.yml", 7, 7, "the sdf export that would write it")]


def test_the_sdf_export_refuses_an_inertia_sdformat_refuses(tmp_path: Path, diags: Diags) -> None:
    spec = _definition(tmp_path, "{type: sdf}")
    compiled = Diags()
    assert compile_file(spec, tmp_path / "out", compiled).out is None
    _take_refusal(compiled, tmp_path)
    assert not compiled.diagnostics and not (tmp_path / "out").exists()
    check_file(spec, diags, Options())  # mpc check says the same, at the same places
    _take_refusal(diags, tmp_path)


@pytest.mark.skipif(IGN is None, reason="ign (ignition-tools + libsdformat12) is not installed")
def test_correct_inertials_makes_an_sdf_that_sdformat_accepts(tmp_path: Path, diags: Diags) -> None:
    spec = _definition(tmp_path, "{type: sdf, correct_inertials: true}")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    assert diags.take("W0530", Severity.WARNING).message == \
        "correct_inertials made the inertials of 1 link physical: 'flat'"
    check_file(spec, diags, Options())  # nothing to refuse: the export corrects it
    run = subprocess.run([IGN or "ign", "sdf", "-k", str(out / "sdf/r.sdf")], capture_output=True, text=True)
    assert "Valid." in run.stdout and "invalid inertia" not in run.stdout + run.stderr


def test_check_reports_a_floating_base_that_clashes(tmp_path: Path, diags: Diags) -> None:
    """A fixed joint named `floating_base` (as in Unitree's models) and add_floating_base:
    compiling refuses it (E0505), and `mpc check` says so before."""
    spec = _definition(tmp_path, "{type: urdf, add_floating_base: true}")
    compiled = Diags()
    assert compile_file(spec, tmp_path / "out", compiled).out is None
    check_file(spec, diags, Options())
    for sink in (diags, compiled):  # once each: the SMURF beside the URDF does not say it again
        error = sink.take_error("E0505")
        assert error.message == ("add_floating_base needs the names 'world' and 'floating_base', but the "
                                 "robot has a joint 'floating_base' already")
        assert (error.span.line, error.span.col) == (7, 7)
        assert error.hint == ("leave out add_floating_base where the robot has a base joint of its own, "
                              "or rename that element (name editing)")
    assert not compiled.diagnostics
