"""Bad input to `mpc deploy` from the command line: each case is one clear diagnostic, exit
status 1 (never 3, an internal error), no traceback, and the remote exactly as it was."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from tests.deploy.conftest import Model, Server, definition_text, git, make_server
from tests.mpc_command import mpc


def _deploy(model: Model, *extra: str | Path) -> subprocess.CompletedProcess[str]:
    args: list[str | Path] = ["deploy", model.definition, "--built", model.built]
    if "--remote" not in extra:
        args += ["--remote", model.folder.parent / "server" / "acme" / "arm-model.git"]
    if "--workdir" not in extra:
        args += ["--workdir", model.folder.parent / "work"]
    return mpc(*args, *extra)


def _fails(run: subprocess.CompletedProcess[str], code: str, message: str) -> None:
    assert run.returncode == 1, run.stderr
    assert "Traceback" not in run.stderr and "internal error" not in run.stderr
    assert f"error[{code}]: {message}" in run.stderr, run.stderr
    assert run.stdout == ""


@pytest.fixture
def used_server(server: Server) -> Server:
    """The model repository with one commit of someone else's, which must stay as it is."""
    server.commit_files({"README.md": "# arm\n"}, "start")
    (server.path / "pushes.jsonl").unlink()  # the hook's record of that push
    return server


@pytest.mark.parametrize("remote", ["file:///nowhere/missing.git", "http://127.0.0.1:9/acme/arm.git"])
def test_a_remote_that_cannot_be_cloned(model: Model, remote: str) -> None:
    model.compile()
    run = _deploy(model, "--remote", remote)
    _fails(run, "E0803", "git clone failed in")
    assert not (model.folder.parent / "work" / "arm-model").exists()


def test_a_remote_address_with_credentials_is_never_shown(model: Model) -> None:
    model.compile()
    run = _deploy(model, "--remote", "http://deployer:s3cr3t-t0ken@127.0.0.1:9/acme/arm.git")
    _fails(run, "E0803", "git clone failed in")
    assert "s3cr3t-t0ken" not in run.stderr and "127.0.0.1:9/acme/arm.git" in run.stderr


def test_a_remote_that_looks_like_an_option_is_refused(model: Model, tmp_path: Path) -> None:
    model.compile()
    run = _deploy(model, "--remote", f"--upload-pack=touch {tmp_path / 'ran'}")
    _fails(run, "E0802", "the model repository's address '--upload-pack=touch")
    assert not (tmp_path / "ran").exists()


def test_an_empty_repository_gets_its_first_commit(model: Model, server: Server) -> None:
    model.compile()
    run = _deploy(model, "--tests-failed")
    assert run.returncode == 0, run.stderr
    assert list(server.branches()) == ["tests-failed"]  # no success branch is made up


@pytest.mark.parametrize(("option", "name"), [("--success-branch", "a..b"), ("--success-branch", "-x"),
                                              ("--failure-branch", "has space"),
                                              ("--failure-branch", "ends.lock")])
def test_a_branch_name_git_refuses(model: Model, used_server: Server, option: str, name: str) -> None:
    before = used_server.branches()
    model.compile()
    run = _deploy(model, f"{option}={name}", "--tests-failed")
    what = option.removeprefix("--").replace("-", " ")
    _fails(run, "E0840", f"{what} '{name}' is not a valid git branch name")
    assert used_server.branches() == before and used_server.pushes() == []


def test_an_mr_target_branch_git_refuses(model: Model, used_server: Server) -> None:
    model.definition.write_text(definition_text("  deployment:\n    mr_target_branch: 'x:y'\n"))
    model.compile()
    run = _deploy(model)
    _fails(run, "E0840", "mr_target_branch 'x:y' is not a valid git branch name")
    assert used_server.pushes() == []


def test_built_is_not_a_folder(model: Model, used_server: Server, tmp_path: Path) -> None:
    model.compile()
    (tmp_path / "file").write_text("x")
    run = mpc("deploy", model.definition, "--built", tmp_path / "file", "--remote", used_server.url,
              "--workdir", tmp_path / "work")
    _fails(run, "E0802", f"the build of 'arm-model' at '{tmp_path / 'file'}' is not a folder")
    assert used_server.pushes() == []


def test_a_protocol_that_is_not_utf8(model: Model, used_server: Server, tmp_path: Path) -> None:
    model.compile()
    protocol = tmp_path / "protocol.md"
    protocol.write_bytes(b"| mass | \xff\xfe passed |\n")
    run = _deploy(model, "--protocol", protocol)
    _fails(run, "E0802", "cannot read the test protocol: it is not UTF-8 text (byte 0xff at offset 9)")
    assert used_server.pushes() == []


def test_a_workdir_that_is_a_file(model: Model, used_server: Server, tmp_path: Path) -> None:
    model.compile()
    (tmp_path / "work").write_text("not a folder")
    run = _deploy(model, "--workdir", tmp_path / "work")
    _fails(run, "E0841", f"cannot use the workdir '{tmp_path / 'work'}':")
    assert used_server.pushes() == []


def test_lfs_patterns_that_match_nothing_are_tracked_all_the_same(model: Model, server: Server) -> None:
    model.definition.write_text(definition_text("  add_lfs_track: [xyz]\n"))
    model.compile()
    run = _deploy(model)
    assert run.returncode == 0, run.stderr
    assert server.show("master", ".gitattributes") == ("*.xyz filter=lfs diff=lfs merge=lfs -text\n"
                                                       "*.XYZ filter=lfs diff=lfs merge=lfs -text")


@pytest.mark.parametrize("kind", ["missing", "empty"])
def test_a_submodule_repository_missing_or_without_commits(model: Model, used_server: Server,
                                                           tmp_path: Path, kind: str) -> None:
    if kind == "empty":
        make_server(tmp_path, "arm-lua")
    model.definition.write_text(definition_text(
        "  deployment:\n    submodules:\n      - {repo: ../arm-lua.git, target: lua}\n"))
    model.compile()
    run = _deploy(model, "--remote", used_server.url)
    lua = f"{tmp_path}/server/acme/arm-lua.git"
    if kind == "missing":
        _fails(run, "E0807", "git fetch failed in")
        assert lua in run.stderr
    else:
        _fails(run, "E0807", f"submodule 'lua': '{lua}' has no branch 'master'")
    assert used_server.pushes() == []


def test_a_modelname_that_is_not_a_folder_name(model: Model, used_server: Server) -> None:
    model.definition.write_text(definition_text().replace("modelname: arm-model", "modelname: ../escape"))
    run = _deploy(model, "--remote", used_server.url)  # the schema refuses it (issue 17)
    _fails(run, "E0250", "'modelname': cannot name a file in the output: it holds a '/' or '\\'")
    assert not (model.folder.parent / "escape").exists() and used_server.pushes() == []


def test_a_workdir_clone_of_the_same_repository_with_another_token(model: Model, tmp_path: Path) -> None:
    """CI tokens change from job to job: mpc's clone is reused, with the new address."""
    model.compile()
    work = tmp_path / "work" / "arm-model"
    git(tmp_path, "init", "-q", str(work))
    git(work, "remote", "add", "origin", "http://ci:old-token-1@127.0.0.1:9/acme/arm.git")
    run = _deploy(model, "--remote", "http://ci:new-token-2@127.0.0.1:9/acme/arm.git")
    _fails(run, "E0803", "git fetch failed in")  # not "a clone of another repository"
    assert "token" not in run.stderr
    assert git(work, "remote", "get-url", "origin") == "http://ci:new-token-2@127.0.0.1:9/acme/arm.git"


def test_a_remote_name_git_refuses(model: Model, used_server: Server,
                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GIT_REMOTE_NAME", "-x")
    model.compile()
    _fails(_deploy(model, "--remote", used_server.url), "E0840",
           "remote name '-x' (GIT_REMOTE_NAME) is not a valid git remote name")
    assert used_server.pushes() == []


def test_a_gitattributes_link_of_the_remote_is_not_written_through(model: Model, used_server: Server,
                                                                   tmp_path: Path) -> None:
    outside = tmp_path / "attributes"
    outside.write_text("")
    work = tmp_path / "linker"
    git(tmp_path, "clone", "-q", used_server.url, str(work))
    (work / ".gitattributes").symlink_to(outside)
    git(work, "add", "-A")
    git(work, "commit", "-q", "-m", "link")
    git(work, "push", "-q", "origin", "HEAD:master")
    (used_server.path / "pushes.jsonl").unlink()
    model.definition.write_text(definition_text("  add_lfs_track: [stl]\n  deployment:\n"
                                                "    keep_files: [.gitattributes]\n"))
    model.compile()
    _fails(_deploy(model, "--remote", used_server.url), "E0804",
           "'.gitattributes' is a symbolic link; git LFS would write through it")
    assert outside.read_text() == "" and used_server.pushes() == []
