"""Nothing outside the target clone is read into a repository or written: symbolic links in
the build or in the remote's tree, git metadata in the build; credentials in addresses and
tokens appear in no output, commit, push option, .gitmodules nor status.json; a moved remote
that conflicts with the update; deployments running at the same time."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mpc.core.diagnostics import Sink
from mpc.deploy import DeploySettings, deploy_model
from tests.conftest import Diags
from tests.deploy.conftest import SMURF_FILES, Model, Server, definition_text, git, heavier, make_server
from tests.mpc_command import mpc


def _plain(model: Model, server: Server) -> DeploySettings:
    return model.settings(remote=server.url, forge="none")


def _push_symlink(server: Server, rel: str, target: str, tmp_path: Path) -> None:
    """Someone commits a symbolic link `rel` → `target` to the remote."""
    work = tmp_path / f"linker-{rel}"
    git(tmp_path, "clone", "-q", server.url, str(work))
    (work / rel).parent.mkdir(parents=True, exist_ok=True)
    (work / rel).symlink_to(target)
    git(work, "add", "-A")
    git(work, "commit", "-q", "-m", "a link")
    git(work, "push", "-q", "origin", "HEAD:master")


def test_a_link_out_of_the_build_is_refused(model: Model, server: Server, tmp_path: Path,
                                            diags: Diags) -> None:
    program = model.compile()
    secret = tmp_path / "secret.txt"
    secret.write_text("private key\n")
    (model.built / "urdf" / "stolen.urdf").symlink_to(secret)
    result = deploy_model(program, model.built, _plain(model, server), diags)
    assert not result.ok and server.branches() == {}
    assert diags.take_error("E0844").message == (
        f"the build's 'urdf/stolen.urdf' is a symbolic link to '{secret}', outside the build; mpc deploys "
        "no file from outside the build")


def test_an_absolute_link_inside_the_build_becomes_relative(model: Model, server: Server) -> None:
    program = model.compile()
    (model.built / "urdf" / "link.urdf").symlink_to(model.built / "urdf" / "arm.urdf")
    result = deploy_model(program, model.built, _plain(model, server), Sink())
    assert result.ok
    assert git(server.path, "ls-tree", "master", "urdf/link.urdf").split()[0] == "120000"
    assert server.show("master", "urdf/link.urdf") == "arm.urdf"


def test_git_metadata_in_the_build_is_left_out(model: Model, server: Server, diags: Diags) -> None:
    program = model.compile()
    nested = model.built / "meshes" / "stl"
    git(nested, "init", "-q")  # meshes/stl/.git: would become an embedded repository
    (model.built / "urdf" / ".git").write_text("gitdir: /somewhere/else\n")
    (model.built / ".gitmodules").write_text('[submodule "x"]\n\tpath = x\n\turl = https://evil.example/x\n')
    result = deploy_model(program, model.built, _plain(model, server), diags)
    assert result.ok
    for entry in (".gitmodules", "meshes/stl/.git", "urdf/.git"):
        assert diags.take("W0840", diags.diagnostics[0].severity).message == (
            f"the build's '{entry}' is not deployed: mpc writes no git metadata from a build into a "
            "repository")
    tree = git(server.path, "ls-tree", "-r", "master").splitlines()
    assert sorted(line.split("\t")[1] for line in tree) == [
        "README.md", "meshes/stl/tetra.stl", "smurf/arm.smurf", *SMURF_FILES, "urdf/arm.urdf"]
    assert {line.split()[0] for line in tree} == {"100644"}  # no gitlink


def test_a_submodule_target_behind_a_link_of_the_remote(model: Model, server: Server, tmp_path: Path,
                                                        diags: Diags) -> None:
    outside = tmp_path / "outside"
    (outside / "lua").mkdir(parents=True)
    (outside / "lua" / "precious.txt").write_text("keep me\n")
    _push_symlink(server, "ext", str(outside), tmp_path)
    make_server(tmp_path, "arm-lua").commit_files({"knee.lua": "--\n"}, "one")
    model.definition.write_text(definition_text(
        "  deployment:\n    submodules:\n      - {repo: ../arm-lua.git, target: ext/lua}\n"))
    before = server.branches()
    result = deploy_model(model.compile(), model.built, _plain(model, server), diags)
    assert not result.ok and server.branches() == before
    assert diags.take_error("E0804").message == ("'ext/lua' would be written outside the repository "
                                                 "(through a symbolic link in it)")
    assert (outside / "lua" / "precious.txt").read_text() == "keep me\n"


def test_kept_files_and_manifest_behind_links_of_the_remote(model: Model, server: Server,
                                                            tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "notes.lua").write_text("-- outside\n")
    _push_symlink(server, "submechanisms", str(outside), tmp_path)  # keep_files: submechanisms/*.lua
    _push_symlink(server, "manifest.xml", str(outside / "manifest.xml"), tmp_path)
    model.definition.write_text(definition_text(
        "  deployment:\n    add_manifest: true\n    keep_files: [submechanisms/*.lua, manifest.xml]\n"))
    result = deploy_model(model.compile(), model.built, _plain(model, server), Sink())
    assert result.ok
    assert sorted(p.name for p in outside.iterdir()) == ["notes.lua"]  # no manifest written through the link
    assert (outside / "notes.lua").read_text() == "-- outside\n"
    assert "submechanisms" not in server.files() and "manifest.xml" in server.files()


def test_a_moved_remote_that_conflicts(model: Model, server: Server, tmp_path: Path) -> None:
    """Someone changes a generated file and a kept file between mpc's fetch and push: the build
    wins for the generated file, theirs for the kept one, and both commits stay in history."""
    server.commit_files({"submechanisms/knee.lua": "-- 1\n"}, "hand-written")
    settings = model.settings(remote=server.url, forge="none")
    first = deploy_model(model.compile(), model.built, settings, Sink())
    clone = settings.workdir / "arm-model"
    marker = tmp_path / "pushed-once"
    other = tmp_path / "other"
    git(tmp_path, "clone", "-q", server.url, str(other))
    hook = clone / ".git" / "hooks" / "pre-push"
    hook.write_text(f"#!/bin/sh\n[ -e '{marker}' ] && exit 0\ntouch '{marker}'\ncd '{other}' && "
                    "echo '<robot name=\"theirs\"/>' > urdf/arm.urdf && "
                    "echo '-- 2' > submechanisms/knee.lua && "
                    "git commit -q -am 'theirs' && git push -q origin HEAD:master\n")
    hook.chmod(0o755)
    result = deploy_model(model.compile(heavier()), model.built, settings, Sink())
    assert result.ok and result.pushed
    assert server.log("master") == ["[mpc] Update arm-model", "theirs", "[mpc] Update arm-model",
                                    "hand-written"]
    assert server.log("master", "%H")[2] == first.commit
    assert '<mass value="12"/>' in server.show("master", "urdf/arm.urdf")
    assert server.show("master", "submechanisms/knee.lua") == "-- 2"
    for push in server.pushes():
        old, new, _ = push["refs"][0]
        if old != "0" * 40:
            assert git(server.path, "merge-base", "--is-ancestor", old, new) == ""


TOKEN = "glpat-SECRET0123456789"


def test_credentials_appear_nowhere(model: Model, server: Server, tmp_path: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """Addresses with a token reach the real repositories (git's insteadOf maps them onto the
    bare repositories); the token shows in no output, commit, push option, .gitmodules nor
    status.json, and the submodule addresses written are without it."""
    base = f"https://deployer:{TOKEN}@git.example.org/acme/"
    config = Path(os.environ["GIT_CONFIG_GLOBAL"])
    config.write_text(config.read_text() + f'[url "{tmp_path}/server/acme/"]\n\tinsteadOf = {base}\n')
    monkeypatch.setenv("GITLAB_TOKEN", "another-secret-value")
    lua = make_server(tmp_path, "arm-lua")
    lua.commit_files({"knee.lua": "--\n"}, "one")
    mirror = make_server(tmp_path, "arm-mirror")
    pipeline = model.folder / "pipeline.yml"
    pipeline.write_text(f"pipeline:\n  root: .\n  model_definitions: [arm_model.yml]\n"
                        f"  remote_base: {base}\n")
    model.definition.write_text(definition_text(f"""\
  deployment:
    mr_target_branch: develop
    mr_title: "Update from {base}"
    submodules:
      - {{repo: ../arm-lua.git, target: lua}}
      - {{repo: "{base}arm-lua.git", target: lua2}}
    mirror: {{repo: "{base}arm-mirror.git", branch: master, submodules: true}}
"""))
    model.compile()
    protocol = tmp_path / "protocol.md"
    protocol.write_text(f"cloned {base}arm-model.git with another-secret-value\n")
    (server.path.parent / "arm-model").symlink_to(server.path)  # remote_base + modelname, no .git
    run = mpc("deploy", model.definition, "--built", model.built, "--pipeline", pipeline,
              "--protocol", protocol)
    assert run.returncode == 0, run.stderr
    staged = mpc("run", pipeline, "--stages", "compile,deploy", "-j", "1")
    status = (model.folder / "build" / ".mpc" / "status.json").read_text()
    assert json.loads(status)["models"]["arm-model"]["stages"]["deploy"]["state"] == "ok", staged.stderr
    texts = [run.stdout, run.stderr, staged.stdout, staged.stderr, status]
    for repo in (server, mirror):
        texts.append(git(repo.path, "log", "--all", "--format=%B"))
        texts.append(json.dumps(repo.pushes()))
        texts.append(repo.show("master", ".gitmodules"))
    for text in texts:
        assert TOKEN not in text and "another-secret-value" not in text
    title = "merge_request.title=Update from https://***@git.example.org/acme/"
    assert title in server.pushes()[0]["options"]
    assert "deployer" not in server.show("master", ".gitmodules")
    assert "https://git.example.org/acme/arm-mirror.git" not in server.show("master", ".gitmodules")
    assert "url = https://git.example.org/acme/arm-lua.git" in mirror.show("master", ".gitmodules")
    assert "url = https://git.example.org/acme/arm-lua.git" in server.show("master", ".gitmodules")


def _second_model(model: Model, name: str) -> Path:
    definition = model.folder / f"{name}.yml"
    definition.write_text(model.definition.read_text().replace("modelname: arm-model", f"modelname: {name}"))
    return definition


def test_deployments_at_the_same_time_share_the_workdir(model: Model, server: Server, tmp_path: Path) -> None:
    lua = make_server(tmp_path, "arm-lua")
    lua.commit_files({"knee.lua": "--\n"}, "one")
    model.definition.write_text(definition_text(
        "  deployment:\n    submodules:\n      - {repo: ../arm-lua.git, target: lua}\n"))
    model.compile()
    other = make_server(tmp_path, "arm-two")
    work = tmp_path / "work"
    jobs = []
    for definition, remote in ((model.definition, server), (_second_model(model, "arm-two"), other),
                               (model.definition, server), (model.definition, server)):
        jobs.append(subprocess.Popen(
            [sys.executable, "-m", "mpc.cli.main", "deploy", str(definition), "--built", str(model.built),
             "--remote", remote.url, "--workdir", str(work)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True))
    outcomes = [(job.wait(), *job.communicate()) for job in jobs]
    assert [code for code, _, _ in outcomes] == [0, 0, 0, 0], outcomes
    assert server.log() == ["[mpc] Update arm-model"] and other.log() == ["[mpc] Update arm-two"]
    assert sum("nothing changed" in out for _, out, _ in outcomes) == 2
    for repo in (server, other):
        assert "lua" in repo.files() and "urdf/arm.urdf" in repo.files()


def test_a_stale_index_lock_of_a_stopped_run_goes(model: Model, server: Server) -> None:
    settings = model.settings(remote=server.url, forge="none")
    deploy_model(model.compile(), model.built, settings, Sink())
    (settings.workdir / "arm-model" / ".git" / "index.lock").write_text("")
    result = deploy_model(model.compile(heavier()), model.built, settings, Sink())
    assert result.ok and result.pushed


def test_a_central_mesh_type_that_is_not_a_folder_name(model: Model, server: Server, tmp_path: Path,
                                                       diags: Diags) -> None:
    settings = model.settings(remote=server.url, remote_base=str(tmp_path / "server"), central_meshes=True,
                              meshes={"../../definitions": "meshes/x"}, forge="none")
    result = deploy_model(model.compile(), model.built, settings, diags)
    assert not result.ok and server.branches() == {}
    assert diags.take_error("E0801").message == ("central mesh type '../../definitions' of the pipeline's "
                                                 "meshes is not a folder name of the build's meshes/")
