"""deploy_model: one built model → its repository (and mirror, and central mesh
repositories), with a merge request through the pipeline's forge.

Phases, each a function of its own module: decide the plan (plan.py); clone or fetch
(repository.py); push central meshes (meshes.py); pin submodules (submodules.py); fill the
tree from the build (content.py, lfs.py); commit with the provenance (provenance.py); push
with the forge's options and open the merge request (forges.py); copy to the mirror
(mirror.py). A failure is one diagnostic; nothing is forced and no branch is deleted.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field
from pathlib import Path

from mpc.compiler.diagnostics import Sink
from mpc.deploy import content, lfs, submodules
from mpc.deploy.forges import MergeRequest, adapter, describe
from mpc.deploy.gitcmd import DeployError
from mpc.deploy.plan import Plan, do_not_deploy, make_plan
from mpc.deploy.provenance import Provenance, commit_message, footer, provenance
from mpc.deploy.repository import Clone, open_clone, publish
from mpc.deploy.settings import DeploySettings
from mpc.ir.program import Program


@dataclass
class DeployResult:
    """What deploying one model did.

    ok: no error (also when there was nothing to do, or `do_not_deploy`).
    commit: the new commit on `branch` of `remote` (None: nothing changed, or a dry run).
    pushed: whether it was pushed. push_options: what the push carried (GitLab's merge
    request). merge_request: the request made, with merge_request_url when the forge says it.
    diffstat: what a dry run would push. meshes: mesh type → commit of its central
    repository. mirror: the mirror's result, if there is a mirror.
    """

    modelname: str
    ok: bool = True
    skipped: bool = False
    remote: str | None = None
    branch: str | None = None
    commit: str | None = None
    pushed: bool = False
    push_options: tuple[str, ...] = ()
    merge_request: MergeRequest | None = None
    merge_request_url: str | None = None
    diffstat: str = ""
    meshes: dict[str, str] = field(default_factory=dict)
    mirror: DeployResult | None = None


def deploy_model(program: Program, built: Path, settings: DeploySettings, sink: Sink, *,
                 protocol_markdown: str | None = None, tests_failed: bool = False) -> DeployResult:
    """Deploy the build of `program` in `built` (what `mpc compile` wrote)."""
    result = DeployResult(program.modelname)
    span = program.deployment.span if program.deployment else program.span
    if do_not_deploy(program, settings):
        result.skipped = True
        return result
    remote = settings.remote_of(program.modelname)
    if not built.is_dir():
        sink.error(span, "E0802", f"the build of '{program.modelname}' is not at '{built}'; compile it first")
        result.ok = False
        return result
    if remote is None:
        sink.error(span, "E0802", f"no repository to deploy '{program.modelname}' to: the pipeline "
                   "has no remote_base (or give --remote)")
        result.ok = False
        return result
    result.remote = remote
    try:
        _deploy(program, built.resolve(), settings, result, protocol_markdown, tests_failed)
    except DeployError as e:
        sink.error(span, e.code, e.message)
        result.ok = False
    return result


def _deploy(program: Program, built: Path, settings: DeploySettings, result: DeployResult,
            protocol: str | None, tests_failed: bool) -> None:
    workdir = settings.workdir.resolve()
    clone = open_clone(result.remote or "", workdir / program.modelname, settings.remote_name)
    plan = make_plan(program, settings, clone.url, clone.default_branch, tests_failed)
    result.branch = plan.branch
    prov = provenance(program, settings.definition_repo, protocol, tests_failed)
    message = commit_message(program, prov)

    pinned = [submodules.pin(s, clone.url, plan.base, workdir) for s in plan.submodules]
    if settings.central_meshes and settings.meshes:
        from mpc.deploy.meshes import deploy_meshes

        mesh_pins = deploy_meshes(built, program.modelname, settings, plan, message, workdir)
        result.meshes = {p.target: p.sha for p in mesh_pins}
        pinned += mesh_pins

    forge = adapter(settings.forge, settings.github_api)
    request = None
    if plan.mr_target is not None and forge.name != "none":
        request = MergeRequest(clone.url, plan.branch, plan.mr_target, plan.mr_title,
                               describe(plan.mr_description, plan.mr_mention, protocol, footer(prov)),
                               plan.mr_mention)
    options = forge.push_options(request) if request else []

    def fill(c: Clone) -> None:
        fill_model(c, built, program, plan, prov, pinned)

    published = publish(clone, plan.branch, plan.base, fill, message, options, settings.dry_run)
    result.commit, result.pushed, result.diffstat = published.sha, published.pushed, published.diffstat
    if published.pushed and request is not None:
        result.push_options = tuple(options)
        result.merge_request = request
        result.merge_request_url = forge.after_push(request, published.output)
    if plan.mirror is not None:
        from mpc.deploy.mirror import deploy_mirror

        result.mirror = deploy_mirror(clone, plan, pinned, settings, message, protocol, prov, workdir)


def fill_model(clone: Clone, built: Path, program: Program, plan: Plan, prov: Provenance,
               pinned: list[submodules.Pinned]) -> None:
    """The model repository's tree: the build, the kept files, README.md, LFS, submodules."""
    folder = clone.folder
    keep = content.kept_files(folder, plan.keep_files)
    if (folder / "README.md").is_file() and not (built / "README.md").exists():
        keep.add("README.md")  # the repository's own README stays; one is written only when missing
    targets = {p.target for p in pinned}
    for target in targets:  # submodules are never checked out here: their folders are empty
        path = folder / target
        if path.is_symlink() or path.is_file():
            path.unlink()
        else:
            shutil.rmtree(path, ignore_errors=True)
    content.replace_content(folder, built, keep - _under(keep, targets), targets)
    content.write_readme(folder, program.modelname, program.robotname, prov.definition_file,
                         plan.mr_mention, bool(plan.lfs_patterns))
    if plan.add_manifest:
        content.write_manifest(folder, program.modelname, program.robotname, plan.mr_mention)
    lfs.track(clone.git, plan.lfs_patterns)
    for target in targets:
        (folder / target).mkdir(parents=True, exist_ok=True)
    clone.git("add", "-A")
    submodules.link(clone.git, pinned)


def _under(paths: set[str], folders: set[str]) -> set[str]:
    return {p for p in paths if any(p == f or p.startswith(f + "/") for f in folders)}

