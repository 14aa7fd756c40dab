"""DeploySettings: the pipeline-level settings of a deployment, from pipeline.yml, the
environment and the command line. It reads no repository.

Branch names keep the environment variables Phobos reads (phobos-ci-behaviour §1.3):
GIT_SUCCESS_BRANCH, GIT_FAILURE_BRANCH (or CI_UPDATE_TARGET_BRANCH), GIT_PRODUCTION_BRANCH,
CI_MESH_UPDATE_TARGET_BRANCH and GIT_REMOTE_NAME. An explicit value wins over them.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import field
from pathlib import Path

from mpc.compiler.schema.definition import PipelineSection
from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.ir.program import Deployment

DEFAULT_FAILURE_BRANCH = "tests-failed"


@record(frozen=False)
class DeploySettings:
    """How models are deployed.

    remote_base: git address prefix; a model's repository is `remote_base` + modelname
        (a `/` is put between them unless remote_base ends with `/` or `:`).
    remote: the address of the model's repository itself (the CLI's --remote); wins over
        remote_base.
    forge: how merge requests are made: `gitlab` (push options), `github` (REST API), `none`.
    uses_lfs, add_lfs_track: track meshes (and these extensions) with git LFS.
    mr_mention: users mentioned in merge requests unless the model names its own.
    central_meshes, meshes: meshes go to shared mesh repositories (`remote_base` + the
        path in `meshes`), linked into each model repository as submodules; otherwise
        they stay inside each model repository.
    add_manifest: write an autoproj manifest.xml into repositories without one.
    default_deployment: the pipeline's `default_deployment`, under each model's own.
    success_branch: where a model that passed its tests goes (None: GIT_SUCCESS_BRANCH,
        else the remote's default branch). failure_branch: where one that failed goes.
    production_branch: the default target of merge requests from the success branch.
    mesh_branch: the branch of the central mesh repositories.
    feature_branch: when set (CI_COMMIT_BRANCH of the form `feature/*`), every model goes
        to this branch, without merge request or mirror (Phobos's feature mode).
    remote_name: the name of the remote in mpc's clones.
    dry_run: prepare the commit, print its diff stat, push nothing.
    workdir: where the clones live (one folder per repository).
    definition_repo: the folder of the model definitions, whose commit the commit message
        records.
    github_api: the GitHub REST API's address (GITHUB_API_URL, else api.github.com).
    """

    remote_base: str | None = None
    remote: str | None = None
    forge: str = "gitlab"
    uses_lfs: bool = False
    add_lfs_track: tuple[str, ...] = ()
    mr_mention: tuple[str, ...] = ()
    central_meshes: bool = False
    meshes: Mapping[str, str] = field(default_factory=dict)
    add_manifest: bool = False
    default_deployment: Deployment | None = None
    success_branch: str | None = None
    failure_branch: str | None = None
    production_branch: str | None = None
    mesh_branch: str | None = None
    feature_branch: str | None = None
    remote_name: str = "origin"
    dry_run: bool = False
    workdir: Path = field(default_factory=lambda: Path("build") / ".deploy")
    definition_repo: Path | None = None
    github_api: str = "https://api.github.com"

    @classmethod
    def from_environment(cls, environ: Mapping[str, str] | None = None, **values: object) -> DeploySettings:
        """Settings with the branch names (and GitHub's API address) the environment gives,
        unless `values` gives them."""
        env = os.environ if environ is None else environ
        found: dict[str, object] = {
            "success_branch": env.get("GIT_SUCCESS_BRANCH") or None,
            "failure_branch": env.get("GIT_FAILURE_BRANCH") or env.get("CI_UPDATE_TARGET_BRANCH") or None,
            "production_branch": env.get("GIT_PRODUCTION_BRANCH") or None,
            "mesh_branch": env.get("CI_MESH_UPDATE_TARGET_BRANCH") or None,
            "feature_branch": _feature(env.get("CI_COMMIT_BRANCH", "")),
            "remote_name": env.get("GIT_REMOTE_NAME") or "origin",
            "github_api": env.get("GITHUB_API_URL") or "https://api.github.com",
        }
        found.update({k: v for k, v in values.items() if v is not None})
        return cls(**found)  # type: ignore[arg-type]

    @classmethod
    def from_pipeline(cls, pipeline: PipelineSection, folder: Path, sink: Sink | None = None,
                      environ: Mapping[str, str] | None = None, **values: object) -> DeploySettings:
        """The settings of a validated pipeline file in `folder`; `values` override them.

        The workdir defaults to `<root>/.mpc-deploy` and the definition repository to
        `folder`. `sink` receives what is wrong with `default_deployment` (E0801).
        """
        from mpc.compiler.lower_deploy import lower_deployment

        default = None
        if pipeline.default_deployment is not None:
            default = lower_deployment(pipeline.default_deployment, sink or Sink())
        root = (folder / os.path.expandvars(pipeline.root)).resolve()
        given: dict[str, object] = {
            "remote_base": pipeline.remote_base, "forge": pipeline.forge, "uses_lfs": pipeline.uses_lfs,
            "add_lfs_track": tuple(pipeline.add_lfs_track), "mr_mention": tuple(pipeline.mr_mention or ()),
            "central_meshes": pipeline.central_meshes, "meshes": dict(pipeline.meshes),
            "add_manifest": pipeline.add_manifest, "default_deployment": default,
            "workdir": root / ".mpc-deploy", "definition_repo": folder.resolve(),
        }
        given.update({k: v for k, v in values.items() if v is not None})
        return cls.from_environment(environ, **given)

    def remote_of(self, modelname: str) -> str | None:
        """The address of a model's repository, or None when neither remote nor remote_base is set."""
        if self.remote:
            return self.remote
        if not self.remote_base:
            return None
        return join_remote(self.remote_base, modelname)


def _feature(branch: str) -> str | None:
    return branch if branch.startswith("feature/") and len(branch) > len("feature/") else None


def join_remote(base: str, path: str) -> str:
    """`base` + `path` with one `/` between them (none after a trailing `:`), unlike Phobos,
    which joins model and mesh repositories differently (phobos-ci-behaviour §8.3)."""
    if base.endswith((":", "/")):
        return base + path.lstrip("/")
    return f"{base}/{path.lstrip('/')}"
