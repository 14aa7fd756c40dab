"""Hostile input and broken disks (issue 17): each class of defect, built in a temporary
folder, gets its diagnostic at its line, exit 1 (never 3), and nothing is written or read
where it must not be."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from mpc.cli.main import main
from tests.conftest import definition, write
from tests.fixtures import arm

TOKEN = "ghp_FAKE0123456789abcdefTOKEN"


def _mpc(capsys: pytest.CaptureFixture[str], *args: str | Path) -> tuple[int, str]:
    code = main([str(a) for a in args])
    return code, capsys.readouterr().err


def _model(tmp_path: Path, text: str | None = None) -> Path:
    arm(tmp_path)
    return write(tmp_path / "model.yml", text or definition("arm.urdf"))


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


# -- 1. output names stay inside the output folder --------------------------------------------

@pytest.mark.parametrize(("key", "old", "new", "line", "col", "why"), [
    ("robotname", "robotname: robot", "robotname: ../../evil", 2, 14, "it holds a '/' or '\\'"),
    ("filename_suffix", "mesh_format: input_type",
     "mesh_format: input_type\n      filename_suffix: /tmp/evil", 12, 24, "it is an absolute path"),
    ("file_name", "mesh_format: input_type",
     "mesh_format: input_type\n    - type: joint_limits\n      file_name: ../../evil.yml", 13, 18,
     "it holds '..', which names a folder outside the file's own"),
])
def test_an_output_name_leading_out_is_reported_by_check_and_nothing_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, old: str, new: str,
        line: int, col: int, why: str) -> None:
    spec = _model(tmp_path / "m", definition("arm.urdf").replace(old, new))
    before = _files(tmp_path)
    code, err = _mpc(capsys, "check", spec)
    assert code == 1
    assert f"{spec}:{line}:{col}: error[E0250]: '{key}': cannot name a file in the output: {why}" in err
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "m/out/x")
    assert code == 1 and "E0250" in err
    assert _files(tmp_path) == before  # not even the output's folder


def test_a_300_character_name_is_reported_at_its_line(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path, definition("arm.urdf") + f"    - type: submodel\n      name: {'a' * 300}\n")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert f"{spec}:13:13: error[E0251]: 'name': a name of 300 bytes cannot name a file in the output; " \
           "at most 200" in err
    assert not (tmp_path / "out").exists()


def test_an_ir_file_with_an_output_name_leading_out(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    code = main(["compile", str(spec), "--emit", "ir"])
    ir = capsys.readouterr().out
    assert code == 0 and 'filename_suffix' not in ir
    bad = write(tmp_path / "bad.ir", ir.replace('robotname="robot"', 'robotname="../evil"'))
    assert 'robotname="../evil"' in bad.read_text()
    code, err = _mpc(capsys, "compile", bad, "-o", tmp_path / "out")
    assert code == 1 and "error[E0250]: 'robotname': cannot name a file in the output" in err
    assert not (tmp_path / "evil.urdf").exists() and not (tmp_path / "out").exists()


# -- 2. inputs are read, never linked through blindly ----------------------------------------

def test_a_mesh_linking_to_a_token_outside_the_package_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    secret = write(tmp_path / "elsewhere/token.stl", f"GITHUB_TOKEN={TOKEN}\n")
    spec = _model(tmp_path / "m")
    mesh = tmp_path / "m/meshes/tetra.stl"
    mesh.unlink()
    mesh.symlink_to(secret)
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "m/out")
    assert code == 1
    assert (f"{tmp_path}/m/arm.urdf:10:33: error[E0650]: mesh 'meshes/tetra.stl' in link 'base' is not "
            f"read: it is a link to '{secret}', outside the model's package roots") in err
    assert not (tmp_path / "m/out").exists()
    assert TOKEN not in err


def test_a_mesh_linking_into_proc_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GITHUB_TOKEN", TOKEN)
    spec = _model(tmp_path)
    mesh = tmp_path / "meshes/tetra.stl"
    mesh.unlink()
    mesh.symlink_to("/proc/self/environ")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1 and "arm.urdf:10:33: error[E0650]" in err and "a special file of the system" in err
    assert not (tmp_path / "out").exists()


def test_a_mesh_linking_inside_the_package_is_copied_as_a_regular_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    mesh = tmp_path / "meshes/tetra.stl"
    mesh.rename(tmp_path / "meshes/real.stl")
    mesh.symlink_to("real.stl")
    code, _ = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    copied = tmp_path / "out/meshes/stl/tetra.stl"
    assert code == 0 and copied.is_file() and not copied.is_symlink()
    assert copied.read_bytes() == (tmp_path / "meshes/real.stl").read_bytes()


# -- 3. the cache verifies what it returns ---------------------------------------------------

def test_an_emptied_cache_entry_is_removed_and_computed_again(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    spec = _model(tmp_path, definition("arm.urdf", mesh_format="obj"))
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "a")[0] == 0
    good = (tmp_path / "a/meshes/obj/tetra.obj").read_bytes()
    (entry,) = (tmp_path / "cache/meshes").rglob("*.obj")
    entry.write_bytes(b"")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "b", "--force")  # not the kept build
    assert code == 0
    assert (f"{tmp_path}/arm.urdf:10:33: warning[W0650]: the cache entry '{entry}' of mesh "
            "'meshes/obj/tetra.obj' is unusable (its bytes do not match their hash); it is removed "
            "and computed again") in err
    assert (tmp_path / "b/meshes/obj/tetra.obj").read_bytes() == good == entry.read_bytes()
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "c", "--force") == (0, "")  # repaired


def test_a_cache_entry_that_is_a_folder_is_replaced(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    spec = _model(tmp_path, definition("arm.urdf", mesh_format="obj"))
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "a")[0] == 0
    (entry,) = (tmp_path / "cache/meshes").rglob("*.obj")
    entry.unlink()
    entry.mkdir()
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "b", "--force")  # not the kept build
    assert code == 0 and "warning[W0650]" in err and "(it is not a regular file)" in err
    assert entry.is_file()


def test_a_cache_folder_that_is_a_file_is_an_error_and_the_previous_output_stays(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _model(tmp_path, definition("arm.urdf", mesh_format="obj"))
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "out")[0] == 0
    before = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    write(tmp_path / "cachefile", "a file\n")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cachefile"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert f"{tmp_path}/arm.urdf:10:33: error[E0652]: cannot compute mesh 'meshes/obj/tetra.obj'" in err
    assert f"cannot write the mesh cache entry '{tmp_path}/cachefile': Not a directory" in err
    assert {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()} == before


# -- 4. the YAML loader is bounded ----------------------------------------------------------

@pytest.mark.parametrize(("text", "code", "line", "col", "message"), [
    ("model:\n  x: " + "[" * 3000 + "]" * 3000 + "\n", "E0110", 2, 204,
     "lists and mappings nested more than 200 deep"),
    ("model:\n  x: &a [1, *a]\n", "E0108", 2, 6, "a recursive alias: the value contains itself"),
    ("model:\n  x: " + "9" * 5000 + "\n", "E0112", 2, 6, "an integer of 5000 digits; at most 100 are read"),
    ("model:\n  robotname: a\x00b\n", "E0107", 2, 15,
     "a non-printable character (#x0000) in YAML; write it escaped in a double-quoted string"),
    ("model:\n  x: " + "y" * (2**20 + 1) + "\n", "E0111", 2, 6,
     "a value of 1048577 characters; at most 1048576 are read"),
])
def test_yaml_beyond_the_loader_s_limits(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         text: str, code: str, line: int, col: int, message: str) -> None:
    spec = tmp_path / "model.yml"
    spec.write_text(text)
    status, err = _mpc(capsys, "check", spec)
    assert status == 1
    assert f"{spec}:{line}:{col}: error[{code}]: {message}" in err


BOMB = "model:\n  l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + "".join(
    f"  l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]\n" for i in range(1, 10))


def test_an_alias_bomb_stops_under_a_memory_limit(tmp_path: Path) -> None:
    spec = write(tmp_path / "model.yml", BOMB)
    limit = 1024 * 2**20  # 10^9 strings would need ~100 GB

    def cap() -> None:
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    run = subprocess.run([sys.executable, "-c", "import sys; from mpc.cli.main import main; "
                          "sys.exit(main(['check', sys.argv[1]]))", str(spec)],
                         capture_output=True, text=True, preexec_fn=cap, timeout=300)
    assert run.returncode == 1, run.stderr
    assert f"{spec}:7:3: error[E0109]: the aliases expand to more than 500000 values" in run.stderr
    assert "Traceback" not in run.stderr


# -- 5. OS errors are diagnostics ------------------------------------------------------------

def test_an_output_through_a_regular_file_is_an_error(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """Tests run as root, whom chmod does not stop: a path through a file fails for anyone."""
    spec = _model(tmp_path)
    write(tmp_path / "afile", "x\n")
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "afile/sub/out")
    assert code == 1
    assert (f"{spec}:1:1: error[E0660]: cannot make the output's folder '{tmp_path}/afile/sub': "
            "Not a directory; the previous output is unchanged") in err


def test_an_output_name_too_long_keeps_the_previous_output(tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    out = tmp_path / ("o" * 300)
    code, err = _mpc(capsys, "compile", spec, "-o", out)
    assert code == 1 and "error[E0660]: cannot move the build into place" in err
    assert "File name too long" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.urdf", "meshes", "model.yml"]


def test_a_basefile_name_too_long(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path, definition("x" * 300 + ".urdf"))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1 and "internal error" not in err
    assert "File name too long" in err


# -- 6. XML fragments stay well-formed -------------------------------------------------------

def test_an_entity_in_a_kept_fragment_is_refused_at_its_line(tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    from tests.fixtures import ARM_URDF

    urdf = ARM_URDF.replace("<robot", '<!DOCTYPE robot [<!ENTITY t "x">]>\n<robot', 1)
    urdf = urdf.replace("</robot>", "  <gazebo><plugin>&t;</plugin></gazebo>\n</robot>")
    spec = _model(tmp_path)
    (tmp_path / "arm.urdf").write_text(urdf)
    line = urdf.splitlines().index("  <gazebo><plugin>&t;</plugin></gazebo>") + 1
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{tmp_path}/arm.urdf:{line}:1: error[E0401]: malformed XML in '{tmp_path}/arm.urdf': "
            "entity reference '&t;' (mpc expands no entities; write the text itself)") in err
    assert not (tmp_path / "out").exists()


# -- 7. the smaller defects ------------------------------------------------------------------

def test_staging_folders_of_killed_builds_are_removed(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    spec = _model(tmp_path)
    dead = subprocess.run(["true"], check=True) and 2**22 + 12345  # beyond pid_max's default
    stale = [tmp_path / f".out.{dead}.abc.mpc-tmp", tmp_path / ".out.k3x_9a1q.mpc-tmp",
             tmp_path / f".out.mpc-old-{dead}"]
    running = tmp_path / f".out.{os.getpid()}.live.mpc-tmp"
    for folder in (*stale, running):
        write(folder / "urdf/robot.urdf", "half\n")
    assert _mpc(capsys, "compile", spec, "-o", tmp_path / "out")[0] == 0
    assert [f for f in stale if f.exists()] == [] and running.exists()


def test_git_runs_never_prompt_and_scrub_credentials(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    from mpc.compiler import repos
    from mpc.core import gitrun

    monkeypatch.delenv("GIT_TERMINAL_PROMPT", raising=False)
    assert gitrun.git("-c", "alias.p=!echo $GIT_TERMINAL_PROMPT", "p") == "0"
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    assert repos._slot("https://ci:token-1@example.org/a.git") == repos._slot(
        "https://ci:token-2@example.org/a.git")
    spec = _model(tmp_path, definition("arm.urdf").replace(
        'basefile: "arm.urdf"',
        'repo: {git: "http://user:s3cret-pw@127.0.0.1:9/arm.git", model_in_repo: arm.urdf}'))
    code, err = _mpc(capsys, "compile", spec, "-o", tmp_path / "out")
    assert code == 1
    assert (f"{spec}:6:13: error[E0604]: cannot get 'HEAD' of repository "
            "'http://***@127.0.0.1:9/arm.git'") in err
    assert "s3cret" not in err.splitlines()[0]  # the message; the source line below is the user's
