"""post_processing: commands run from the command line's `mpc compile` on a real model."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.conftest import ERD, write
from tests.mpc_command import mpc

SOURCE = ERD / "talos_data/robots/talos_left_arm.urdf"
HEAD = f"""
model:
  robotname: arm
  modelname: talos_arm
  input_models: {{arm: {{basefile: "{SOURCE}"}}}}
  assemble: {{model: arm}}
"""


def tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_commands_run_in_order_in_the_output_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A string without shell is split (Phobos's check_urdf line runs, urdfdom's real tool);
    a shell line sees MPC_* and PHOBOS_CI_* (and not mpc's own OPENBLAS_NUM_THREADS); a cwd is
    relative to the definition; the ROS files come after the commands and list the folder they
    made."""
    for own in ("MPC_CACHE_DIR", "MPC_MESH_WORKERS"):  # the user's own MPC_* is not mpc's to set
        monkeypatch.delenv(own, raising=False)
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)  # mpc's own setting is not the command's
    (tmp_path / "scripts").mkdir()
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config: [{type: urdf, mesh_format: stl, ros_pathes: true}]
  post_processing:
    - cmd: "check_urdf urdf/arm.urdf"
    - cmd: 'mkdir -p doc && check_urdf urdf/arm.urdf > doc/tree.txt && pwd > doc/ran_in.txt'
      shell: true
    - cmd: [sh, -c, 'env | grep -E "^(MPC|PHOBOS_CI)_" | sort > "$MPC_EXPORTDIR/env.txt";
                     pwd > "$MPC_EXPORTDIR/cwd.txt"; echo "${OPENBLAS_NUM_THREADS-unset}" > blas.txt']
      cwd: scripts
""")
    done = mpc("compile", spec, "-o", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    out = tmp_path / "out"
    assert "robot name is: arm" in (out / "doc/tree.txt").read_text()
    staging = Path((out / "doc/ran_in.txt").read_text().strip())
    assert staging.parent == tmp_path and staging.name.startswith(".out.") and not staging.exists()
    env = dict(line.split("=", 1) for line in (out / "env.txt").read_text().splitlines())
    assert env == {"MPC_DEFINITIONDIR": str(tmp_path), "MPC_EXPORTDIR": str(staging),
                   "MPC_TARGETDIR": str(out), "PHOBOS_CI_DEFINITIONDIR": str(tmp_path),
                   "PHOBOS_CI_EXPORTDIR": str(staging), "PHOBOS_CI_TARGETDIR": str(out)}
    assert (out / "cwd.txt").read_text().strip() == str(tmp_path / "scripts")
    assert (tmp_path / "scripts/blas.txt").read_text() == "unset\n"
    assert "  doc\n  meshes\n  smurf\n  urdf\n" in (out / "CMakeLists.txt").read_text()


def test_a_failing_command_fails_the_build_and_keeps_the_last_output(tmp_path: Path) -> None:
    good = write(tmp_path / "m.yml", HEAD)
    assert mpc("compile", good, "-o", tmp_path / "out").returncode == 0
    before = tree(tmp_path / "out")
    bad = write(tmp_path / "m.yml", HEAD + """
  post_processing:
    - cmd: [sh, -c, 'echo checking; echo "inertia of arm_left_4_link is not positive" >&2; exit 3']
    - cmd: [touch, "$MPC_DEFINITIONDIR/never"]
""")
    done = mpc("compile", bad, "-o", tmp_path / "out")
    assert done.returncode == 1
    lines = done.stderr.splitlines()
    assert lines[0] == (f"{bad}:8:12: error[E0508]: post_processing command `sh -c 'echo checking; "
                        "echo \"inertia of arm_left_4_link is not positive\" >&2; exit 3'` failed with "
                        "exit status 3")
    assert lines[3:6] == ["  note: its output ends:", "    checking",
                          "    inertia of arm_left_4_link is not positive"]
    assert tree(tmp_path / "out") == before
    assert not (tmp_path / "never").exists() and not list(tmp_path.glob(".out.*"))


def test_a_program_that_is_not_there(tmp_path: Path) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  post_processing:
    - cmd: [mpc-no-such-program, urdf/arm.urdf]
""")
    done = mpc("compile", spec, "-o", tmp_path / "out", "--format", "gcc")
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == (f"{spec}:8:12: error: post_processing command "
                                           "`mpc-no-such-program urdf/arm.urdf` could not start: "
                                           "No such file or directory [E0508]")
    assert not (tmp_path / "out").exists()


def test_shell_syntax_without_shell_is_an_error_and_with_shell_writes_its_file(tmp_path: Path) -> None:
    """Phobos ran `cmd` through a shell; without `shell`, `> log.txt` would be an argument and
    nothing would be written, so mpc refuses it (mpc check too) and builds nothing."""
    line = "    - cmd: \"python3 -c 'print(42)' > log.txt\"\n"
    spec = write(tmp_path / "m.yml", HEAD + "  post_processing:\n" + line)
    for command in ("check", "compile"):
        done = mpc(command, spec, "-o", tmp_path / "out") if command == "compile" else mpc(command, spec)
        assert done.returncode == 1
        assert f"{spec}:7:12: error[E0560]: this command has shell syntax (`'`) but runs without a " \
               "shell" in done.stderr, done.stderr
        assert "add `shell: true` to run it through /bin/sh, or give `cmd` as a list" in done.stderr
    assert not (tmp_path / "out").exists()
    write(spec, HEAD + "  post_processing:\n" + line + "      shell: true\n")
    done = mpc("compile", spec, "-o", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/log.txt").read_text() == "42\n"


# -- what a command gets of the environment, and when it runs (issue 35.7) -----------------------

TOKEN = "ghp_FAKE0123456789abcdefTOKEN"
DUMP_ENV = "    - cmd: [sh, -c, 'env | sort > \"$MPC_EXPORTDIR/env.txt\"']\n"


def _environment(out: Path) -> dict[str, str]:
    return dict(line.split("=", 1) for line in (out / "env.txt").read_text().splitlines() if "=" in line)


def test_a_command_gets_path_home_the_listed_variables_and_no_token(tmp_path: Path) -> None:
    spec = write(tmp_path / "m.yml", HEAD + "  export_config: [{type: urdf, mesh_format: stl}]\n"
                 "  post_processing:\n" + DUMP_ENV + "      env: [MPC_TEST_WANTED, MPC_TEST_UNSET]\n")
    done = mpc("compile", spec, "-o", tmp_path / "out", env={
        **os.environ, "GITHUB_TOKEN": TOKEN, "CI_JOB_TOKEN": TOKEN, "MPC_TEST_WANTED": "yes"})
    assert done.returncode == 0, done.stderr
    env = _environment(tmp_path / "out")
    assert env["MPC_TEST_WANTED"] == "yes" and "MPC_TEST_UNSET" not in env
    assert {"PATH", "HOME", "MPC_EXPORTDIR", "PHOBOS_CI_TARGETDIR"} <= set(env)
    assert TOKEN not in (tmp_path / "out" / "env.txt").read_text()
    # what sh sets itself (PWD, SHLVL, _) and nothing else of mpc's environment
    assert set(env) - {"PWD", "SHLVL", "_", "OLDPWD"} == {
        "PATH", "HOME", "MPC_TEST_WANTED", *(f"{p}_{n}" for p in ("MPC", "PHOBOS_CI")
                                             for n in ("EXPORTDIR", "TARGETDIR", "DEFINITIONDIR"))}


def test_a_listed_name_that_is_no_variable_is_an_error_at_its_line(tmp_path: Path) -> None:
    spec = write(tmp_path / "m.yml", HEAD + "  post_processing:\n" + DUMP_ENV + "      env: [OK, 'A=B']\n")
    done = mpc("check", spec)
    assert done.returncode == 1
    assert (f"{spec}:8:17: error[E0541]: 'A=B' is not the name of an environment variable "
            "(letters, digits and '_', not a digit first)") in done.stderr


def test_check_and_no_post_processing_run_nothing(tmp_path: Path) -> None:
    canary = tmp_path / "canary"
    spec = write(tmp_path / "m.yml", HEAD + "  export_config: [{type: urdf, mesh_format: stl}]\n"
                 f"  post_processing:\n    - cmd: [touch, '{canary}']\n")
    assert mpc("check", spec).returncode == 0
    assert not canary.exists()
    done = mpc("compile", spec, "-o", tmp_path / "out", "--no-post-processing")
    assert done.returncode == 0, done.stderr
    assert not canary.exists() and (tmp_path / "out/urdf/arm.urdf").is_file()
    done = mpc("compile", spec, "-o", tmp_path / "out")  # not the build above, kept: it runs
    assert done.returncode == 0, done.stderr
    assert canary.exists()
    canary.unlink()
    done = mpc("compile", spec, "-o", tmp_path / "out", "--no-post-processing")
    assert done.returncode == 0 and not canary.exists()
