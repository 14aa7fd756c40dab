"""The small parts of deploy: lowering, settings from the environment, the shallow merge,
LFS patterns, credential scrubbing, submodule addresses, GitHub repository names."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.compiler.driver import Options
from mpc.compiler.front_end import load_program
from mpc.core.span import Span
from mpc.deploy.gitcmd import scrub
from mpc.deploy.github import repository_slug
from mpc.deploy.plan import lfs_patterns, make_plan, merged
from mpc.deploy.settings import DeploySettings, join_remote
from mpc.deploy.submodules import absolute_url
from mpc.ir.program import Deployment, DeployMirror, Program
from tests.conftest import Diags
from tests.deploy.conftest import definition_text
from tests.fixtures import arm

S = Span("d.yml", 1, 1)


def _program(tmp_path: Path, deployment: str, diags: Diags) -> Program | None:
    arm(tmp_path)
    (tmp_path / "arm_model.yml").write_text(definition_text(deployment))
    return load_program(tmp_path / "arm_model.yml", diags, Options())


def test_deployment_is_lowered(tmp_path: Path, diags: Diags) -> None:
    program = _program(tmp_path, """\
  add_lfs_track: [bobj]
  deployment:
    do_not_deploy: false
    mr_mention: "@alice"
    keep_files: ["a/*.lua"]
    mirror: {repo: ../m.git, merge_request: true}
""", diags)
    assert program is not None and program.deployment is not None
    d = program.deployment
    assert (d.do_not_deploy, d.mr_mention, d.keep_files, d.add_lfs_track, d.mr_title) == (
        False, ("@alice",), ("a/*.lua",), ("bobj",), None)
    assert d.mirror == DeployMirror(repo="../m.git", span=d.mirror.span, merge_request=True)
    assert (d.span.line, d.span.col) == (13, 3)


def test_keep_files_outside_the_repository(tmp_path: Path, diags: Diags) -> None:
    _program(tmp_path, """\
  deployment:
    keep_files: ["../secret", "ok/*"]
    submodules: [{repo: x.git, target: /abs}]
""", diags)
    keep, target = diags.take_error("E0801"), diags.take_error("E0801")
    assert keep.message == ("keep_files entry '../secret' is outside the repository; write a path "
                            "relative to the repository's top folder")
    assert (keep.span.line, keep.span.col) == (13, 18)
    assert target.message == "submodule target '/abs' is not a folder inside the repository"


def test_settings_from_the_environment_and_explicit_values() -> None:
    env = {"GIT_SUCCESS_BRANCH": "main", "CI_UPDATE_TARGET_BRANCH": "update", "GIT_REMOTE_NAME": "autobuild",
           "GIT_PRODUCTION_BRANCH": "stable", "CI_MESH_UPDATE_TARGET_BRANCH": "meshes"}
    s = DeploySettings.from_environment(env, failure_branch="broken")
    assert (s.success_branch, s.failure_branch, s.production_branch, s.mesh_branch, s.remote_name) == (
        "main", "broken", "stable", "meshes", "autobuild")
    assert DeploySettings.from_environment({}).failure_branch is None
    assert DeploySettings.from_environment({"GIT_FAILURE_BRANCH": "f", "CI_UPDATE_TARGET_BRANCH": "u"}) \
        .failure_branch == "f"


def test_remote_addresses() -> None:
    assert join_remote("git@host:models", "arm") == "git@host:models/arm"
    assert join_remote("git@host:", "arm") == "git@host:arm"
    assert join_remote("https://h/g/", "/meshes/stl") == "https://h/g/meshes/stl"
    assert DeploySettings(remote_base="https://h/g").remote_of("arm") == "https://h/g/arm"
    assert DeploySettings(remote_base="https://h/g", remote="r").remote_of("arm") == "r"
    assert DeploySettings().remote_of("arm") is None


def test_shallow_merge_of_default_deployment() -> None:
    default = Deployment(span=S, do_not_deploy=True, mr_title="T", keep_files=("a",), mr_mention=("@x",))
    own = Deployment(span=Span("m.yml", 3, 3), do_not_deploy=False, keep_files=("b",))
    m = merged(default, own)
    assert m == Deployment(span=own.span, do_not_deploy=False, mr_title="T", keep_files=("b",),
                           mr_mention=("@x",))
    assert merged(None, own) is own and merged(default, None) is default


@pytest.mark.parametrize(("failed", "production", "target", "expected"), [
    (False, None, None, ("master", None)),            # success = production: no merge request
    (False, "stable", None, ("master", "stable")),
    (True, None, None, ("tests-failed", "master")),   # a failure asks to go into the success branch
    (True, None, "develop", ("tests-failed", "develop")),
    (False, None, "master", ("master", None)),        # a request into the branch itself is none
])
def test_branches_and_merge_request_target(failed: bool, production: str | None, target: str | None,
                                           expected: tuple[str, str | None]) -> None:
    program = Program(robotname="r", modelname="m", inputs={}, ops=(), exports=(), span=S,
                      deployment=Deployment(span=S, mr_target_branch=target))
    plan = make_plan(program, DeploySettings(production_branch=production), "url", "master", failed)
    assert (plan.branch, plan.mr_target) == expected
    assert plan.base == "master"


def test_lfs_patterns() -> None:
    assert lfs_patterns(("Bobj", ".ply"), False) == ("*.Bobj", "*.bobj", "*.BOBJ", "*.ply", "*.PLY")
    assert lfs_patterns((), True)[:3] == ("*.obj", "*.OBJ", "*.stl")
    assert lfs_patterns((), False) == ()


def test_scrub(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GITHUB_TOKEN", "tok-12345")
    assert scrub("fatal: https://user:pa55@host/x.git and ssh://git@host/y") == \
        "fatal: https://***@host/x.git and ssh://***@host/y"
    assert scrub("header tok-12345 echoed") == "header *** echoed"


def test_submodule_addresses() -> None:
    assert absolute_url("../lua.git", "https://h/g/arm.git") == "https://h/g/lua.git"
    assert absolute_url("../../other/lua.git", "git@h:g/arm.git") == "git@h:other/lua.git"
    assert absolute_url("./sub", "/srv/arm") == "/srv/arm/sub"
    assert absolute_url("https://x/y.git", "/srv/arm") == "https://x/y.git"


def test_github_repository_names() -> None:
    assert repository_slug("git@github.com:acme/arm.git") == "acme/arm"
    assert repository_slug("https://github.com/acme/arm") == "acme/arm"
    assert repository_slug("https://token@github.com/acme/arm.git/") == "acme/arm"
    assert repository_slug("/srv/git/acme/arm.git") == "acme/arm"
    assert repository_slug("arm") is None


@pytest.mark.parametrize(("path", "inside"), [
    ("a/b.lua", True), ("**/*.lua", True), ("./a", True), (".", False), ("", False),
    ("../a", False), ("a/../../b", False), ("/etc/passwd", False)])
def test_inside_repository(path: str, inside: bool) -> None:
    from mpc.compiler.lower_deploy import inside_repository

    assert inside_repository(path) is inside


def test_keep_files_and_targets_in_git_s_own_folder_or_not_globs(tmp_path: Path, diags: Diags) -> None:
    _program(tmp_path, """\
  deployment:
    keep_files: [".git/hooks/*", "a**b", "ok/**/*.lua"]
    submodules: [{repo: x.git, target: .git}, {repo: x.git, target: sub/.git/x}]
""", diags)
    assert diags.take_error("E0801").message == ("keep_files entry '.git/hooks/*' is outside the repository; "
                                                 "write a path relative to the repository's top folder")
    assert diags.take_error("E0845").message == ("keep_files entry 'a**b' is not a glob: '**' stands only "
                                                 "for whole folders, as in 'a/**/*.lua'")
    for target in (".git", "sub/.git/x"):
        assert diags.take_error("E0801").message == (f"submodule target '{target}' is not a folder inside "
                                                     "the repository")


def test_git_never_works_on_a_repository_around_its_folder(tmp_path: Path) -> None:
    from mpc.deploy.gitcmd import DeployError, Git
    from tests.deploy.conftest import git

    git(tmp_path, "init", "-q")
    (tmp_path / "clone").mkdir()
    with pytest.raises(DeployError, match="not a git repository"):
        Git(tmp_path / "clone")("status")


def test_no_nul_byte_reaches_git(tmp_path: Path) -> None:
    from mpc.deploy.forges import GitLab
    from mpc.deploy.gitcmd import DeployError, Git
    from mpc.deploy.merge_request import MergeRequest, describe

    description = describe("text\0", ("@a",), "proto\0col", "footer")
    assert description == "text\n\n@a\n\nprotocol\n\nfooter\n"
    options = GitLab().push_options(MergeRequest("r", "s", "t", "ti\0tle", description, ()))
    assert options[2] == "merge_request.title=title"
    with pytest.raises(DeployError, match="cannot take an argument with a NUL byte"):
        Git(tmp_path)("commit", "-m", "a\0b")


def test_credentials_are_left_out_of_written_addresses() -> None:
    from mpc.deploy.gitcmd import without_credentials

    assert without_credentials("https://ci:tok@h.org/a/b.git") == "https://h.org/a/b.git"
    assert without_credentials("https://tok@h.org/a") == "https://h.org/a"
    assert without_credentials("ssh://git:pw@h.org:22/a") == "ssh://git@h.org:22/a"
    assert without_credentials("ssh://git@h.org/a") == "ssh://git@h.org/a"
    assert without_credentials("git@h.org:a/b.git") == "git@h.org:a/b.git"
