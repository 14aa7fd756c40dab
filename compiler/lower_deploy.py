"""AST `deployment` (and the model's `add_lfs_track`) → ir.Deployment.

Lowering keeps what is not given as None, so that the pipeline's `default_deployment`
can fill it when deploying (deploy/plan.py). It checks that `keep_files` and submodule
targets stay inside the repository; it contacts no repository.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import PurePosixPath

from mpc.compiler.schema.definition import ModelSection
from mpc.compiler.schema.release import DeploymentSection
from mpc.core.diagnostics import Sink
from mpc.ir.program import Deployment, DeployMirror, DeploySubmodule


def inside_repository(path: str) -> bool:
    """Whether a path (or glob) written in a definition stays inside the repository, and out
    of git's own `.git` folder (a submodule target `.git` would have the clone's deleted)."""
    pure = PurePosixPath(path.replace("\\", "/"))
    return bool(pure.parts) and not pure.is_absolute() and not {"..", ".git"} & set(pure.parts)


def usable_glob(pattern: str) -> bool:
    """Whether `pattern` is a glob pathlib can match (`**` only as a whole path component)."""
    return all(part == "**" or "**" not in part for part in PurePosixPath(pattern).parts)


def lower_deployment(section: DeploymentSection, sink: Sink) -> Deployment:
    """The IR of a `deployment` section (a model's, or the pipeline's `default_deployment`)."""
    keep = []
    for i, pattern in enumerate(section.keep_files):
        if not inside_repository(pattern):
            sink.error(section.value_span("keep_files", i), "E0801",
                       f"keep_files entry '{pattern}' is outside the repository; write a path "
                       "relative to the repository's top folder")
            continue
        if not usable_glob(pattern):
            sink.error(section.value_span("keep_files", i), "E0845",
                       f"keep_files entry '{pattern}' is not a glob: '**' stands only for whole "
                       "folders, as in 'a/**/*.lua'")
            continue
        keep.append(pattern)
    submodules = []
    for sub in section.submodules:
        if not inside_repository(sub.target) or sub.target.endswith("/"):
            sink.error(sub.value_span("target"), "E0801",
                       f"submodule target '{sub.target}' is not a folder inside the repository")
            continue
        submodules.append(DeploySubmodule(repo=sub.repo, target=sub.target, span=sub.span,
                                          commit=sub.commit, branch=sub.branch))
    mirror = None
    if section.mirror is not None:
        m = section.mirror
        mirror = DeployMirror(repo=m.repo, span=m.span, branch=m.branch, submodules=m.submodules,
                              merge_request=m.merge_request, mr_title=m.mr_title, mr_target=m.mr_target,
                              mr_mention=None if m.mr_mention is None else tuple(m.mr_mention))
    given = section.given
    return Deployment(
        span=section.span,
        do_not_deploy=section.do_not_deploy if "do_not_deploy" in given else None,
        mr_target_branch=section.mr_target_branch, mr_title=section.mr_title,
        mr_description=section.mr_description,
        mr_mention=None if section.mr_mention is None else tuple(section.mr_mention),
        keep_files=tuple(keep), submodules=tuple(submodules), mirror=mirror,
        add_manifest=section.add_manifest,
        add_lfs_track=None if section.add_lfs_track is None else tuple(section.add_lfs_track))


def lower_model_deployment(model: ModelSection, sink: Sink) -> Deployment | None:
    """The model's deployment: its `deployment` section, with the model-level `add_lfs_track`
    when the section does not give one; None when the definition says nothing of either."""
    lfs = None if model.add_lfs_track is None else tuple(model.add_lfs_track)
    if model.deployment is None:
        if lfs is None:
            return None
        return Deployment(span=model.key_span("add_lfs_track"), add_lfs_track=lfs)
    deployment = lower_deployment(model.deployment, sink)
    if deployment.add_lfs_track is None and lfs is not None:
        deployment = replace(deployment, add_lfs_track=lfs)
    return deployment

