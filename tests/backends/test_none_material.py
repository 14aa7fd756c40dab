"""Phobos's colourless material `None` (issue 29, point 8): left out with a warning naming it,
so that check_urdf has nothing to say about mpc's URDF."""

from __future__ import annotations

import subprocess
from pathlib import Path

from mpc.core.diagnostics import Severity
from tests.conftest import Diags, compile_file, definition, write

# As Phobos writes a visual without a material: a reference to 'None', defined nowhere.
URDF = """\
<robot name="robot">
  <link name="a"><visual><geometry><box size="1 1 1"/></geometry><material name="None"/></visual></link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  <link name="b"><visual><geometry><box size="1 1 1"/></geometry><material name="None"/></visual></link>
</robot>
"""


def test_the_colourless_none_material_is_left_out_with_a_warning(tmp_path: Path, diags: Diags) -> None:
    source = write(tmp_path / "phobos.urdf", URDF)
    before = subprocess.run(["check_urdf", str(source)], capture_output=True, text=True)
    assert before.stderr.count("material 'None' undefined") == 4  # what the issue saw, per link
    spec = write(tmp_path / "m.yml", definition(source))
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    warning = diags.take("W0621", Severity.WARNING)
    assert warning.message == ("material 'None' has no colour (Phobos writes it for visuals without a "
                               "material); it is left out, from the visuals of links 'a', 'b'")
    assert (Path(warning.span.file).name, warning.span.line) == ("phobos.urdf", 2)
    written = out / "urdf/robot.urdf"
    assert "None" not in written.read_text()
    after = subprocess.run(["check_urdf", str(written)], capture_output=True, text=True)
    assert after.returncode == 0 and "undefined" not in after.stderr + after.stdout
