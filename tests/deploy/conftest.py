"""Real git for deploy tests: bare "server" repositories on disk whose pre-receive hook
records every push (its push options and ref updates), a compiled arm model, and a git
that reads no user or system configuration."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

from mpc.compiler.driver import Options, compile_model
from mpc.compiler.front_end import load_program
from mpc.core.diagnostics import Sink
from mpc.deploy import DeploySettings
from mpc.ir.program import Program
from tests.fixtures import ARM_URDF, arm

# The arm's SMURF annotation files beside `smurf/arm.smurf` (Phobos's set: every category
# the arm has elements of).
SMURF_FILES = ("smurf/arm_collisions.yml", "smurf/arm_joints.yml", "smurf/arm_links.yml",
               "smurf/arm_visuals.yml")
IDENTITY = {"GIT_AUTHOR_NAME": "Test Author", "GIT_AUTHOR_EMAIL": "author@example.org",
            "GIT_COMMITTER_NAME": "Test Committer", "GIT_COMMITTER_EMAIL": "committer@example.org"}

HOOK = """\
#!{python}
import json, os, sys
count = int(os.environ.get("GIT_PUSH_OPTION_COUNT", "0"))
options = [os.environ[f"GIT_PUSH_OPTION_{{i}}"] for i in range(count)]
refs = [line.split() for line in sys.stdin.read().splitlines()]
with open(os.path.join(os.environ.get("GIT_DIR", "."), "pushes.jsonl"), "a") as log:
    log.write(json.dumps({{"options": options, "refs": refs}}) + "\\n")
"""


@pytest.fixture(autouse=True)
def clean_git(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """git with a known identity and no global or system configuration."""
    home = tmp_path_factory.mktemp("home")
    config = home / "gitconfig"
    config.write_text("[init]\n\tdefaultBranch = master\n[protocol \"file\"]\n\tallow = always\n")
    monkeypatch.setenv("GIT_CONFIG_GLOBAL", str(config))
    monkeypatch.setenv("GIT_CONFIG_NOSYSTEM", "1")
    monkeypatch.setenv("HOME", str(home))
    for name in ("GIT_SUCCESS_BRANCH", "GIT_FAILURE_BRANCH", "CI_UPDATE_TARGET_BRANCH",
                 "GIT_PRODUCTION_BRANCH", "CI_MESH_UPDATE_TARGET_BRANCH", "GIT_REMOTE_NAME",
                 "GITHUB_TOKEN", "GH_TOKEN", "GITHUB_API_URL"):
        monkeypatch.delenv(name, raising=False)
    for key, value in IDENTITY.items():
        monkeypatch.setenv(key, value)


def git(folder: Path, *args: str) -> str:
    run = subprocess.run(["git", *args], cwd=folder, check=True, capture_output=True, text=True)
    return run.stdout.strip()


@dataclass
class Server:
    """A bare repository standing in for the forge's git server."""

    path: Path

    @property
    def url(self) -> str:
        return str(self.path)

    def pushes(self) -> list[dict]:
        log = self.path / "pushes.jsonl"
        return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []

    def branches(self) -> dict[str, str]:
        out = git(self.path, "for-each-ref", "--format=%(refname:short) %(objectname)", "refs/heads")
        return dict(line.split() for line in out.splitlines())

    def show(self, rev: str, path: str) -> str:
        return git(self.path, "show", f"{rev}:{path}")

    def files(self, rev: str = "master") -> list[str]:
        return git(self.path, "ls-tree", "-r", "--name-only", rev).splitlines()

    def log(self, rev: str = "master", fmt: str = "%s") -> list[str]:
        return git(self.path, "log", f"--format={fmt}", rev).splitlines()

    def message(self, rev: str = "master") -> str:
        return git(self.path, "log", "-1", "--format=%B", rev)

    def commit_files(self, files: dict[str, str], message: str, branch: str = "master",
                     work: Path | None = None) -> str:
        """Push a commit with `files` from a clone of its own (another user's push)."""
        work = work or self.path.parent / f"{self.path.stem}-other"
        if not work.exists():
            git(self.path.parent, "clone", "-q", str(self.path), str(work))
        git(work, "fetch", "-q", "origin")
        if git(work, "ls-remote", "origin", f"refs/heads/{branch}"):
            git(work, "checkout", "-q", "-B", branch, f"origin/{branch}")
        for rel, text in files.items():
            (work / rel).parent.mkdir(parents=True, exist_ok=True)
            (work / rel).write_text(text)
        git(work, "add", "-A")
        git(work, "commit", "-q", "-m", message)
        git(work, "push", "-q", "origin", f"HEAD:refs/heads/{branch}")
        return git(work, "rev-parse", "HEAD")


def make_server(folder: Path, name: str) -> Server:
    path = folder / "server" / "acme" / f"{name}.git"
    path.mkdir(parents=True)
    git(path, "init", "-q", "--bare", "-b", "master")
    git(path, "config", "receive.advertisePushOptions", "true")
    hook = path / "hooks" / "pre-receive"
    hook.write_text(HOOK.format(python=sys.executable))
    hook.chmod(0o755)
    return Server(path)


@pytest.fixture
def server(tmp_path: Path) -> Server:
    return make_server(tmp_path, "arm-model")


DEPLOYMENT = """\
  deployment:
    mr_target_branch: develop
    mr_title: New arm model
    mr_mention: ["@alice", "@bob"]
    keep_files:
      - submechanisms/*.lua
"""


def definition_text(deployment: str = DEPLOYMENT) -> str:
    return textwrap.dedent("""\
        model:
          robotname: arm
          modelname: arm-model
          input_models:
            arm:
              basefile: arm.urdf
          assemble:
            model: arm
          export_config:
            - type: urdf
              mesh_format: stl
        """) + deployment


@dataclass
class Model:
    """A model definition in its own git repository, and its build."""

    folder: Path
    built: Path

    @property
    def definition(self) -> Path:
        return self.folder / "arm_model.yml"

    def program(self) -> Program:
        sink = Sink()
        program = load_program(self.definition, sink, Options())
        assert program is not None and not sink.diagnostics, sink.diagnostics
        return program

    def compile(self, urdf: str = ARM_URDF) -> Program:
        """Compile (after writing `urdf` as the arm) into `built`; commit the definitions."""
        arm(self.folder, urdf)
        sink = Sink()
        result = compile_model(self.definition, sink, Options(out=self.built))
        assert result.out is not None and result.program is not None, sink.diagnostics
        git(self.folder, "add", "-A")
        if git(self.folder, "status", "--porcelain"):
            git(self.folder, "commit", "-q", "-m", "definitions")
        return result.program

    def settings(self, **values: object) -> DeploySettings:
        values.setdefault("workdir", self.folder.parent / "work")
        values.setdefault("definition_repo", self.folder)
        values.setdefault("forge", "gitlab")
        return DeploySettings.from_environment(**values)


@pytest.fixture
def model(tmp_path: Path) -> Model:
    folder = tmp_path / "definitions"
    folder.mkdir()
    git(folder, "init", "-q")
    (folder / "arm_model.yml").write_text(definition_text())
    return Model(folder, tmp_path / "build" / "arm-model")


def heavier(urdf: str = ARM_URDF) -> str:
    """The arm with a heavier first link: a changed model."""
    assert '<mass value="' in urdf
    return urdf.replace('<mass value="', '<mass value="1', 1)
