"""Submodules, mirrors, central mesh repositories and Git LFS, on bare repositories."""

from __future__ import annotations

from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.deploy import deploy_model
from tests.conftest import Diags
from tests.deploy.conftest import SMURF_FILES, Model, Server, definition_text, git, heavier, make_server


def _plain(model: Model, server: Server) -> object:
    return model.settings(remote=server.url, forge="none")


def _gitmodules(server: Server, rev: str = "master") -> dict[str, str]:
    out = git(server.path, "config", "--blob", f"{rev}:.gitmodules", "--list")
    return dict(line.split("=", 1) for line in out.splitlines())


def _gitlink(server: Server, path: str, rev: str = "master") -> str:
    mode, kind, sha, _ = git(server.path, "ls-tree", rev, path).split(maxsplit=3)
    assert (mode, kind) == ("160000", "commit")
    return sha


def test_submodules_are_pinned_to_their_branch_or_commit(model: Model, server: Server,
                                                         tmp_path: Path) -> None:
    lua = make_server(tmp_path, "arm-lua")
    first = lua.commit_files({"knee.lua": "-- 1\n"}, "one")
    newest = lua.commit_files({"knee.lua": "-- 2\n"}, "two")
    model.definition.write_text(definition_text(f"""\
  deployment:
    submodules:
      - repo: ../arm-lua.git
        target: lua
      - repo: ../arm-lua.git
        target: old/lua
        commit: "{first[:10]}"
"""))
    result = deploy_model(model.compile(), model.built, _plain(model, server), Sink())
    assert result.ok, result
    assert _gitmodules(server) == {
        "submodule.lua.path": "lua", "submodule.lua.url": "../arm-lua.git",
        "submodule.lua.branch": "master",
        "submodule.old/lua.path": "old/lua", "submodule.old/lua.url": "../arm-lua.git",
        "submodule.old/lua.branch": "master"}
    assert (_gitlink(server, "lua"), _gitlink(server, "old/lua")) == (newest, first)
    # A clone with --recurse-submodules gets the files: the relative address works on the server.
    checkout = tmp_path / "checkout"
    git(tmp_path, "clone", "-q", "--recurse-submodules", server.url, str(checkout))
    assert (checkout / "lua/knee.lua").read_text() == "-- 2\n"
    assert (checkout / "old/lua/knee.lua").read_text() == "-- 1\n"
    # Deploying again changes nothing; a submodule that is no longer listed goes.
    again = deploy_model(model.compile(), model.built, _plain(model, server), Sink())
    assert again.commit is None
    model.definition.write_text(definition_text(""))
    deploy_model(model.compile(), model.built, _plain(model, server), Sink())
    assert ".gitmodules" not in server.files() and "lua" not in server.files()


def test_unknown_submodule_commit(model: Model, server: Server, tmp_path: Path, diags: Diags) -> None:
    make_server(tmp_path, "arm-lua").commit_files({"knee.lua": "--\n"}, "one")
    model.definition.write_text(definition_text("""\
  deployment:
    submodules:
      - {repo: ../arm-lua.git, target: lua, commit: 0123456789abcdef}
"""))
    result = deploy_model(model.compile(), model.built, _plain(model, server), diags)
    assert not result.ok and server.branches() == {}
    d = diags.take_error("E0807")
    assert d.message == (f"submodule 'lua': '{tmp_path}/server/acme/arm-lua.git' has no commit "
                         "'0123456789abcdef'")


def test_mirror_gets_a_copy_with_submodule_files(model: Model, server: Server, tmp_path: Path) -> None:
    lua = make_server(tmp_path, "arm-lua")
    lua.commit_files({"knee.lua": "-- lua\n"}, "one")
    mirror = make_server(tmp_path, "arm-mirror")
    mirror.commit_files({"LICENSE": "x\n"}, "start")
    model.definition.write_text(definition_text(f"""\
  deployment:
    submodules:
      - {{repo: ../arm-lua.git, target: lua}}
    mirror:
      repo: {mirror.url}
      branch: develop
      merge_request: true
      mr_title: Mirrored arm
"""))
    result = deploy_model(model.compile(), model.built, model.settings(remote=server.url), Sink())
    assert result.ok and result.mirror is not None and result.mirror.pushed
    assert sorted(mirror.files("develop")) == ["README.md", "lua/knee.lua", "meshes/stl/tetra.stl",
                                               "smurf/arm.smurf", *SMURF_FILES, "urdf/arm.urdf"]
    assert mirror.log("develop") == ["[mpc] Update arm-model", "start"]
    options = mirror.pushes()[-1]["options"]
    assert options[:3] == ["merge_request.create", "merge_request.target=master",
                           "merge_request.title=Mirrored arm"]


def test_mirror_with_submodules_uses_absolute_addresses(model: Model, server: Server,
                                                        tmp_path: Path) -> None:
    lua = make_server(tmp_path, "arm-lua")
    sha = lua.commit_files({"knee.lua": "-- lua\n"}, "one")
    mirror = make_server(tmp_path, "arm-mirror")
    model.definition.write_text(definition_text(f"""\
  deployment:
    submodules:
      - {{repo: ../arm-lua.git, target: lua}}
    mirror: {{repo: {mirror.url}, branch: master, submodules: true}}
"""))
    result = deploy_model(model.compile(), model.built, _plain(model, server), Sink())
    assert result.ok and result.mirror is not None and result.mirror.pushed
    assert _gitmodules(mirror)["submodule.lua.url"] == lua.url
    assert _gitlink(mirror, "lua") == sha


def test_central_meshes_go_to_mesh_repositories(model: Model, tmp_path: Path) -> None:
    server = make_server(tmp_path, "arm-model")
    meshes = tmp_path / "server" / "acme" / "meshes" / "stl"
    meshes.mkdir(parents=True)
    git(meshes, "init", "-q", "--bare", "-b", "master")
    settings = model.settings(remote_base=str(tmp_path / "server" / "acme") + "/", central_meshes=True,
                              meshes={"stl": "meshes/stl"}, forge="none")
    server_model = Server(tmp_path / "server" / "acme" / "arm-model")
    # remote_base + modelname: the model repository is <base>/arm-model (no .git suffix)
    git(server.path.parent, "init", "-q", "--bare", "-b", "master", "arm-model")
    result = deploy_model(model.compile(), model.built, settings, Sink())
    assert result.ok, result
    mesh_sha = git(meshes, "rev-parse", "master")
    assert result.meshes == {"meshes/stl": mesh_sha}
    assert git(meshes, "ls-tree", "-r", "--name-only", "master").splitlines() == ["tetra.stl"]
    assert "meshes/stl/tetra.stl" not in server_model.files()
    assert _gitlink(server_model, "meshes/stl") == mesh_sha
    assert _gitmodules(server_model)["submodule.meshes/stl.url"] == str(meshes)
    checkout = tmp_path / "checkout"
    git(tmp_path, "clone", "-q", "--recurse-submodules", str(server_model.path), str(checkout))
    mesh = "meshes/stl/tetra.stl"
    assert (checkout / mesh).read_bytes() == (model.built / mesh).read_bytes()
    # The mesh repository pools meshes: another model's file stays.
    Server(meshes).commit_files({"other.stl": "solid other\n"}, "another model")
    deploy_model(model.compile(heavier()), model.built, settings, Sink())
    assert sorted(git(meshes, "ls-tree", "-r", "--name-only", "master").splitlines()) == ["other.stl",
                                                                                           "tetra.stl"]


def test_lfs_tracks_meshes(model: Model, server: Server) -> None:
    settings = model.settings(remote=server.url, forge="none", uses_lfs=True, add_lfs_track=("urdf",))
    result = deploy_model(model.compile(), model.built, settings, Sink())
    assert result.ok
    attributes = server.show("master", ".gitattributes").splitlines()
    assert "*.stl filter=lfs diff=lfs merge=lfs -text" in attributes
    assert "*.STL filter=lfs diff=lfs merge=lfs -text" in attributes
    assert "*.urdf filter=lfs diff=lfs merge=lfs -text" in attributes
    pointer = server.show("master", "meshes/stl/tetra.stl")
    assert pointer.startswith("version https://git-lfs.github.com/spec/v1\noid sha256:")
    oid = pointer.split("oid sha256:")[1].split()[0]
    stored = server.path / "lfs" / "objects" / oid[:2] / oid[2:4] / oid
    assert stored.read_bytes() == (model.built / "meshes/stl/tetra.stl").read_bytes()
    assert "Git LFS" in server.show("master", "README.md")


def test_mirror_of_an_lfs_repository_stores_pointers_too(model: Model, server: Server,
                                                         tmp_path: Path) -> None:
    mirror = make_server(tmp_path, "arm-mirror")
    model.definition.write_text(definition_text(
        f"  deployment:\n    mirror: {{repo: {mirror.url}, branch: master}}\n"))
    settings = model.settings(remote=server.url, forge="none", uses_lfs=True)
    result = deploy_model(model.compile(), model.built, settings, Sink())
    assert result.ok and result.mirror is not None and result.mirror.pushed
    for repo in (server, mirror):
        pointer = repo.show("master", "meshes/stl/tetra.stl")
        assert pointer.startswith("version https://git-lfs.github.com/spec/v1")
    assert list((mirror.path / "lfs" / "objects").rglob("*")) != []
