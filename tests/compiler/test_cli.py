"""`mpc compile` from the command line: outputs, exit codes and diagnostics as users see them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from lxml import etree

from tests.conftest import definition, write
from tests.fixtures import arm

ROOT = Path(__file__).resolve().parents[2]


def mpc(*args: str | Path, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "mpc.compiler.cli", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd)


def test_bundled_example_compiles(tmp_path: Path) -> None:
    run = mpc("compile", ROOT / "examples/talos.yml", "-o", tmp_path / "talos")
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    assert run.stdout == (f"compiled '{ROOT}/examples/talos.yml' into '{tmp_path}/talos': "
                          "smurf/talos.smurf, smurf/talos_collisions.yml, smurf/talos_joints.yml, "
                          "smurf/talos_links.yml, smurf/talos_materials.yml, smurf/talos_visuals.yml, "
                          "urdf/talos.urdf and 48 mesh files\n")
    urdf = etree.parse(str(tmp_path / "talos/urdf/talos.urdf")).getroot()
    assert urdf.get("name") == "talos"
    assert {m.get("filename").rsplit("/", 1)[0] for m in urdf.iter("mesh")} == {"../meshes/stl"}


def test_default_output_folder_is_build_modelname(tmp_path: Path) -> None:
    arm(tmp_path)
    write(tmp_path / "model.yml", definition("arm.urdf", "stl", "arm"))
    run = mpc("compile", "model.yml", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "build/arm-model/urdf/arm.urdf").is_file()
    assert (tmp_path / "build/arm-model/meshes/stl/tetra.stl").is_file()


def test_errors_are_shown_with_source_line_and_caret(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "model.yml", definition("arm.urdf").replace("robotname:", "robtname:"))
    run = mpc("compile", spec)
    assert run.returncode == 1
    assert run.stdout == ""
    assert run.stderr == (
        f"{spec}:2:3: error[E0201]: unknown key 'robtname' in model; did you mean 'robotname'?\n"
        " 2 |   robtname: robot\n"
        "   |   ^^^^^^^^\n"
        f"{spec}:1:1: error[E0203]: model has no 'robotname', which is required\n"
        " 1 | model:\n"
        "   | ^^^^^\n"
        f"error: could not compile '{spec}' (2 errors)\n"
    )


def test_gcc_and_json_formats(tmp_path: Path) -> None:
    spec = write(tmp_path / "model.yml", definition("missing.urdf"))
    gcc = mpc("compile", spec, "--format", "gcc")
    assert gcc.returncode == 1
    assert gcc.stderr == (f"{spec}:6:17: error: basefile '{tmp_path}/missing.urdf' of input "
                          "model 'base' does not exist [E0601]\n")
    js = mpc("compile", spec, "--format", "json")
    assert js.returncode == 1
    [d] = json.loads(js.stderr)
    assert d["code"] == "E0601" and d["severity"] == "error"
    assert d["span"] == {"file": str(spec), "line": 6, "col": 17, "end_line": 6, "end_col": 31}


def test_broken_urdf_points_into_the_urdf(tmp_path: Path) -> None:
    source = arm(tmp_path)
    source.write_text(source.read_text().replace('<mass value="1"/>', '<mass value="1kg"/>'))
    spec = write(tmp_path / "model.yml", definition("arm.urdf"))
    run = mpc("compile", spec)
    assert run.returncode == 1
    assert "Traceback" not in run.stderr
    assert run.stderr.splitlines()[:3] == [
        f"{source}:23:20: error[E0404]: 'value' of <mass> in link 'upper' must be a number, got '1kg'",
        ' 23 |       <mass value="1kg"/>',
        "    |                    ^^^",
    ]


def test_usage_errors_exit_2() -> None:
    assert mpc().returncode == 2
    assert mpc("compile").returncode == 2
    assert mpc("compile", "x.yml", "--package", "nodir").returncode == 2


def test_check_imports_no_heavy_library() -> None:
    """`mpc check` runs on every save in editors: YAML, the schema and URDF names, nothing more."""
    heavy = ("pinocchio", "pybullet", "trimesh", "numpy", "scipy", "lark", "pydantic", "git")
    probe = ("import sys\nfrom mpc.compiler.cli import main\n"
             f"code = main(['check', {str(ROOT / 'examples/talos.yml')!r}])\n"
             f"print(code, [m for m in {heavy!r} if m in sys.modules])\n")
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert run.stderr == ""
    assert run.stdout.splitlines()[-1] == "0 []"
