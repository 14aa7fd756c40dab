"""`mpc compile` from the command line: outputs, exit codes and diagnostics as users see them."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
from pathlib import Path

from lxml import etree

from tests.conftest import definition, write
from tests.fixtures import arm
from tests.mpc_command import mpc, mpc_process

ROOT = Path(__file__).resolve().parents[2]


def test_bundled_example_compiles(tmp_path: Path) -> None:
    run = mpc_process("compile", ROOT / "examples/talos.yml", "-o", tmp_path / "talos")
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
    assert js.stderr == ""
    [d] = json.loads(js.stdout)
    assert d["code"] == "E0601" and d["severity"] == "error"
    assert d["span"] == {"file": str(spec), "line": 6, "col": 17, "end_line": 6, "end_col": 31}


def test_json_is_one_document_on_stdout_and_the_rest_goes_to_stderr(tmp_path: Path) -> None:
    arm(tmp_path)
    good = write(tmp_path / "good.yml", definition("arm.urdf", "stl", "arm"))
    bad = write(tmp_path / "bad.yml", definition("missing.urdf"))
    built = mpc("compile", good, "-o", tmp_path / "out", "--format", "json")
    assert built.returncode == 0, built.stderr
    assert json.loads(built.stdout) == []
    assert built.stderr == (f"compiled '{good}' into '{tmp_path}/out': smurf/arm.smurf, "
                            "smurf/arm_collisions.yml, smurf/arm_joints.yml, smurf/arm_links.yml, "
                            "smurf/arm_visuals.yml, urdf/arm.urdf and 1 mesh files\n")
    checked = mpc("check", good, bad, bad, "--format", "json")
    assert checked.returncode == 1
    assert [(d["code"], d["span"]["file"]) for d in json.loads(checked.stdout)] == [
        ("E0601", str(bad)), ("E0601", str(bad))]
    ir = mpc("compile", bad, "--emit", "ir", "--format", "json")  # stdout is the IR's
    assert (ir.returncode, ir.stdout) == (1, "")
    assert [d["code"] for d in json.loads(ir.stderr)] == ["E0601"]


def test_version_and_schema_go_to_stdout(tmp_path: Path) -> None:
    from mpc.compiler.jsonschema import render
    from mpc.core.version import mpc_version

    version = mpc("--version")
    assert (version.returncode, version.stdout) == (0, f"mpc {mpc_version()}\n")
    assert mpc_version() != "unknown"
    schema = mpc("schema", cwd=tmp_path)
    assert (schema.returncode, schema.stdout) == (0, render())
    assert list(tmp_path.iterdir()) == []  # nothing written where the user stands
    written = mpc("schema", "-o", tmp_path / "s.json")
    assert (written.returncode, written.stdout) == (0, f"wrote {tmp_path / 's.json'}\n")
    assert (tmp_path / "s.json").read_text() == render()


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
    """`mpc check` runs on every save in editors: YAML, the schema and URDF names, nothing
    more."""
    heavy = ("pinocchio", "pybullet", "trimesh", "numpy", "scipy", "lark", "git")
    probe = ("import sys\nfrom mpc.cli.main import main\n"
             f"code = main(['check', {str(ROOT / 'examples/talos.yml')!r}])\n"
             f"print(code, [m for m in {heavy!r} if m in sys.modules])\n")
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert run.stderr == ""
    assert run.stdout.splitlines()[-1] == "0 []"


def test_package_paths_are_found_in_a_sourced_ros2_workspace(tmp_path: Path) -> None:
    """AMENT_PREFIX_PATH: each prefix's `share/<package>`, as `ros2 pkg prefix` finds it."""
    import os

    from tests.fixtures import ARM_URDF, tetra_stl

    tetra_stl(tmp_path / "ws/install/arm_description/share/arm_description/meshes/tetra.stl")
    write(tmp_path / "models/arm.urdf",
          ARM_URDF.replace("meshes/tetra.stl", "package://arm_description/meshes/tetra.stl"))
    spec = write(tmp_path / "models/model.yml", definition("arm.urdf", "stl", "arm"))
    missing = mpc("compile", spec, "-o", tmp_path / "out", "--format", "gcc")
    assert missing.returncode == 1
    assert "package 'arm_description' was not found (searched the package map, ROS_PACKAGE_PATH, " \
           "AMENT_PREFIX_PATH, the Python environment and the folders above the model)" in missing.stderr
    env = {**os.environ, "AMENT_PREFIX_PATH": f"{tmp_path}/ws/install/other{os.pathsep}"
                                              f"{tmp_path}/ws/install/arm_description"}
    found = subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o",
                            str(tmp_path / "out")], capture_output=True, text=True, env=env)
    assert found.returncode == 0, found.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == (
        tmp_path / "ws/install/arm_description/share/arm_description/meshes/tetra.stl").read_bytes()


def test_a_colcon_symlink_install_workspace_is_read_through_its_links(tmp_path: Path) -> None:
    """`colcon build --symlink-install` links install/<pkg>/share/<pkg>/meshes/… into src/:
    links inside the workspace of a sourced prefix are read; one out of it is still refused."""
    import os

    from tests.fixtures import ARM_URDF, tetra_stl

    ws = tmp_path / "ws"
    tetra_stl(ws / "src/arm_description/meshes/tetra.stl")
    share = ws / "install/arm_description/share/arm_description"
    share.mkdir(parents=True)
    (share / "meshes").symlink_to(ws / "src/arm_description/meshes")
    write(tmp_path / "models/arm.urdf",
          ARM_URDF.replace("meshes/tetra.stl", "package://arm_description/meshes/tetra.stl"))
    spec = write(tmp_path / "models/model.yml", definition("arm.urdf", "stl", "arm"))
    env = {**os.environ, "AMENT_PREFIX_PATH": str(ws / "install/arm_description")}
    run = [sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o", str(tmp_path / "out")]
    done = subprocess.run(run, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == (
        ws / "src/arm_description/meshes/tetra.stl").read_bytes()
    tetra_stl(tmp_path / "elsewhere/tetra.stl")
    (ws / "src/arm_description/meshes/tetra.stl").unlink()
    (ws / "src/arm_description/meshes/tetra.stl").symlink_to(tmp_path / "elsewhere/tetra.stl")
    refused = subprocess.run([*run, "--format", "gcc"], capture_output=True, text=True, env=env)
    assert refused.returncode == 1
    assert "[E0650]" in refused.stderr


def test_the_program_ends_with_mains_status_its_atexit_work_done_and_its_output_whole(
        tmp_path: Path) -> None:
    """`mpc` skips the interpreter's teardown (cli/main.py: program); what users see of the
    end stays: the exit status, every byte written to a pipe (by Python or by C's stdio), and
    the atexit functions run (multiprocessing's and tempfile's among them). The cyclic
    collector paused for a compile stays off to the end (turned on, it would scan everything
    once more); main() called in a process that goes on leaves it as it was."""
    arm(tmp_path)
    good = write(tmp_path / "good.yml", definition("arm.urdf"))
    bad = write(tmp_path / "bad.yml", definition("arm.urdf").replace("robotname:", "robtname:"))
    probe = ("import atexit, ctypes, gc, sys\nfrom mpc.cli.main import program\n"
             "atexit.register(lambda: print('atexit ran', file=sys.stderr))\n"
             "atexit.register(lambda: print('collector on:', gc.isenabled(), file=sys.stderr))\n"
             "print('before mpc', end='')  # left in the buffer of a pipe\n"
             "ctypes.CDLL(None).printf(b' and C')  # in C's, as a C library prints\n"
             "sys.argv = ['mpc', *sys.argv[1:]]\nprogram()\n")
    buffered = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    for args, status in (([good, "-o", tmp_path / "out"], 0), ([bad], 1), (["--bogus"], 2)):
        run = subprocess.run([sys.executable, "-c", probe, "compile", *map(str, args)],
                             capture_output=True, text=True, timeout=600, env=buffered)
        assert run.returncode == status, run.stderr
        assert run.stdout.startswith("before mpc") and run.stdout.endswith(" and C")
        assert run.stderr.endswith(f"collector on: {status == 2}\natexit ran\n")
    assert (tmp_path / "out/urdf/robot.urdf").is_file()
    assert gc.isenabled()
    assert mpc("compile", good, "-o", tmp_path / "again").returncode == 0
    assert gc.isenabled()
    assert mpc_process("compile", bad).stderr.endswith(f"error: could not compile '{bad}' (2 errors)\n")
