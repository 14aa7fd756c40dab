"""The mjcf export options `additional_meshes`, `enforce_zero` and `float_fmt_dict`, and why
`ros_pathes` / `copy_with_other_pathes` are refused there (E0550) — from the command line, on
example-robot-data's talos arm, checked in MuJoCo."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from tests.conftest import ERD, write
from tests.mpc_command import mpc

ARM = ERD / "talos_data/robots/talos_left_arm.urdf"


def _spec(tmp_path: Path, exports: str, extra: str = "") -> Path:
    return write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm_model
          input_models: {{base: {{basefile: "{ARM}"}}}}
          assemble: {{model: base}}
        {extra}
          export_config:
        {exports}
        """)


def _bodies(xml: Path) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """Each body's world position and rotation at qpos0, and its mass, as MuJoCo reads it."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(xml))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return {model.body(i).name: (data.xpos[i].copy(), data.xmat[i].reshape(3, 3).copy(),
                                 float(model.body_mass[i])) for i in range(1, model.nbody)}


def test_float_fmt_dict_additional_meshes_and_enforce_zero(tmp_path: Path) -> None:
    """`%.6f` for every number, `%.3e` for masses; OBJ meshes beside the STL ones, referenced by
    nothing; a 1e-17 offset (and MuJoCo's computed quaternions) written as 0. MuJoCo reads the
    formatted file as the exact one, to the formats' precision; a rebuild gives the same bytes."""
    spec = _spec(tmp_path, """
            - {type: mjcf, mesh_format: stl, additional_meshes: obj, enforce_zero: true,
               float_fmt_dict: {default: "%.6f", mass: "%.3e"}}
            - {type: mjcf, mesh_format: stl, filename_suffix: _exact}
        """, extra="  frames:\n            arm_left_2_link: {transform_frame: {xyz: [0, 0, 1e-17]}}")
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    assert sorted(p.stem for p in (out / "meshes/obj").iterdir()) == sorted(
        p.stem for p in (out / "meshes/stl").iterdir())
    text = (out / "mjcf/arm.xml").read_text()
    assert "meshes/obj" not in text and "e-17" not in text
    assert "e-17" in (out / "mjcf/arm_exact.xml").read_text()
    root = etree.fromstring(text.encode())
    for attr in ("pos", "quat", "diaginertia", "range", "axis"):
        values = [e.get(attr) for e in root.iter() if e.get(attr) is not None]
        assert values and all(re.fullmatch(r"(-?\d+\.\d{6} ?)+", v) for v in values), attr
    masses = [e.get("mass") for e in root.iter("inertial")]
    assert masses and all(re.fullmatch(r"\d\.\d{3}e[-+]\d\d", m) for m in masses)
    assert root.find("compiler").get("boundmass") == "0"  # a setting, not a number of the robot
    formatted, exact = _bodies(out / "mjcf/arm.xml"), _bodies(out / "mjcf/arm_exact.xml")
    assert formatted.keys() == exact.keys()
    for name, (pos, rot, mass) in exact.items():
        assert np.allclose(formatted[name][0], pos, atol=1e-5)
        assert np.allclose(formatted[name][1], rot, atol=1e-5)
        assert abs(formatted[name][2] - mass) <= 5e-4 * mass
    again = mpc("compile", spec, "-o", tmp_path / "again")
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "again/mjcf/arm.xml").read_bytes() == (out / "mjcf/arm.xml").read_bytes()


def test_package_paths_on_mjcf_are_an_error(tmp_path: Path) -> None:
    spec = _spec(tmp_path, "    - {type: mjcf, mesh_format: stl, ros_pathes: true}")
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 1
    assert ("error[E0550]: 'ros_pathes' writes package:// mesh paths, which MuJoCo cannot resolve: "
            "it reads mesh files relative to the MJCF file (or its meshdir), and knows no ROS "
            "packages") in run.stderr
    assert not (tmp_path / "out").exists()


def test_mujoco_cannot_resolve_a_package_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """The reason for E0550: MuJoCo reads `package://` as a file name and fails, even when the
    package's folder is on ROS_PACKAGE_PATH."""
    import mujoco

    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ERD))
    mesh = next((ERD / "talos_data/meshes/arm").glob("*.STL"))
    xml = (f'<mujoco><asset><mesh name="m" file="package://talos_data/meshes/arm/{mesh.name}"/></asset>'
           '<worldbody><geom type="mesh" mesh="m"/></worldbody></mujoco>')
    with pytest.raises(ValueError, match="Error opening file 'package:/talos_data/meshes/arm/"):
        mujoco.MjModel.from_xml_string(xml)
