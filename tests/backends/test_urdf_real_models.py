"""Every URDF of example-robot-data, compiled through a one-input definition, is the
same robot: physically identical in Pinocchio (its visuals and collisions too), every
gazebo/transmission/mimic kept, accepted by check_urdf."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pinocchio as pin
import pytest
from lxml import etree

from tests.backends.pin_compare import assert_same_physics, assert_same_shapes
from tests.conftest import ERD, ERD_PACKAGE, Diags, compile_file, definition, write

ALL = sorted(str(p.relative_to(ERD)) for p in ERD.rglob("*.urdf"))
# The two broken models of the package; their diagnostics are tested below.
BROKEN = {
    "ur_description/urdf/ur3.urdf": "an empty stub: <robot> without name or links",
    "romeo_description/urdf/romeo_laas_small.urdf": "its 20 Ogre .mesh files are missing",
}
GOOD = [m for m in ALL if m not in BROKEN]


def _count(path: Path, tag: str) -> int:
    return len(etree.parse(str(path)).getroot().findall(f".//{tag}"))


def test_pinocchio_loads_every_model_but_the_empty_stub() -> None:
    """Guards the list above: the models this file calls good are all Pinocchio can load."""
    failing = []
    for model in ALL:
        try:
            pin.buildModelFromUrdf(str(ERD / model))
        except (RuntimeError, ValueError):
            failing.append(model)
    assert failing == ["ur_description/urdf/ur3.urdf"]
    assert len(GOOD) == 67


@pytest.mark.parametrize("model", GOOD)
def test_compiled_model_is_the_same_robot(model: str, tmp_path: Path) -> None:
    source = ERD / model
    spec = write(tmp_path / "model.yml", definition(source, robotname=source.stem))
    sink = Diags()
    result = compile_file(spec, tmp_path / "out", sink)
    assert [d for d in sink.diagnostics if d.severity.value == "error"] == []
    assert result.out is not None
    out = result.out / "urdf" / f"{source.stem}.urdf"

    assert_same_physics(source, out)
    assert_same_shapes(source, out, [str(ERD_PACKAGE.parent)])
    for tag in ("gazebo", "transmission", "mimic", "ros2_control"):
        assert _count(out, tag) == _count(source, tag), tag
    checked = subprocess.run([shutil.which("check_urdf") or "check_urdf", str(out)],
                             capture_output=True, text=True)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    # Every mesh the URDF names was copied next to it.
    for mesh in etree.parse(str(out)).getroot().iter("mesh"):
        assert (out.parent / mesh.get("filename")).is_file()


def test_empty_stub_is_a_diagnostic_naming_file_and_element(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "model.yml", definition(ERD / "ur_description/urdf/ur3.urdf"))
    assert compile_file(spec, tmp_path / "out", diags).out is None
    no_name = diags.take_error("E0403")
    assert no_name.message == f"<robot> in '{ERD}/ur_description/urdf/ur3.urdf' has no 'name' attribute"
    assert (no_name.span.line, no_name.span.col) == (6, 1)
    no_links = diags.take_error("E0415")
    assert no_links.message == f"robot '?' in '{ERD}/ur_description/urdf/ur3.urdf' has no links"
    assert not (tmp_path / "out").exists()


def test_missing_meshes_are_diagnostics_naming_file_link_and_element(
        tmp_path: Path, diags: Diags) -> None:
    source = ERD / "romeo_description/urdf/romeo_laas_small.urdf"
    spec = write(tmp_path / "model.yml", definition(source))
    assert compile_file(spec, tmp_path / "out", diags).out is None
    mesh = "/usr/Romeo/naoqi-sdk-2.3.0.14-linux64/share/alrobotmodel/meshes/romeo/TrunkYaw.mesh"
    first = diags.take_error("E0602")
    assert first.message == f"mesh file '{mesh}' of a visual of link 'body' does not exist"
    assert first.span.file == str(source)
    line = source.read_text().splitlines()[first.span.line - 1]
    assert line[first.span.col - 1:first.span.end_col - 1] == f"file://{mesh}"
    for _ in range(19):
        assert "does not exist" in diags.take_error("E0602").message
