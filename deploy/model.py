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
from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.deploy import content, lfs, names, submodules
from mpc.deploy.forges import adapter
from mpc.deploy.gitcmd import DeployError, scrub
from mpc.deploy.merge_request import merge_request
from mpc.deploy.pictures import FOLDER, copy_pictures
from mpc.deploy.plan import Plan, check_plan_branches, do_not_deploy, make_plan
from mpc.deploy.provenance import Provenance, commit_message, footer, provenance
from mpc.deploy.repository import Clone, locked, open_clone, publish
from mpc.deploy.result import DeployResult, record_push
from mpc.deploy.review import Review, release_review
from mpc.deploy.settings import DeploySettings
from mpc.deploy.test_outcome import TestOutcome, test_outcome
from mpc.ir.program import Program


def deploy_model(program: Program, built: Path, settings: DeploySettings, sink: Sink, *,
                 protocol_markdown: str | None = None, tests_failed: bool = False,
                 pictures: Path | None = None, review: Review | None = None) -> DeployResult:
    """Deploy the build of `program` in `built` (what `mpc compile` wrote).

    protocol_markdown, tests_failed: the caller's test protocol and verdict; without a
    protocol, the one `mpc test` wrote into the build decides (deploy/test_outcome.py), and a
    protocol that says its tests failed sends the model to the failure branch.
    pictures: the folder of the protocol's pictures (`test_pictures/` beside it), committed
    with the model when it is not the build's own; the merge request links them.
    review: makes the changes against the release (deploy/review.py) that the merge
    request's description starts with; their pictures are committed and linked too.

    Models deployed at the same time (a pipeline's workers, or two CI jobs) may share the
    workdir: each holds the lock of its own clone, and the shared caches have locks of their own.
    """
    result = DeployResult(program.modelname)
    span = program.deployment.span if program.deployment else program.span
    if do_not_deploy(program, settings):
        result.skipped = True
        return result
    try:
        remote = _checked_inputs(program, built, settings)
        result.remote = scrub(remote)
        for entry in content.not_deployed(built):
            sink.warning(span, "W0840", f"the build's '{entry}' is not deployed: mpc writes no git "
                         "metadata from a build into a repository")
        tests = test_outcome(built, protocol_markdown, tests_failed)
        workdir = _workdir(settings.workdir)
        with locked(workdir / program.modelname):
            _deploy(program, built.resolve(), remote, workdir, settings, result, tests, pictures, review)
    except DeployError as e:
        sink.error(span, e.code, e.message)
        result.ok = False
    except OSError as e:
        where = f": '{e.filename}'" if e.filename else ""
        sink.error(span, "E0843", scrub(f"deploying '{program.modelname}' failed on a file: "
                                        f"{e.strerror or e}{where}"))
        result.ok = False
    return result


def _checked_inputs(program: Program, built: Path, settings: DeploySettings) -> str:
    """The model repository's address, once the build, the names and the branches given are sound."""
    if not built.exists():
        raise DeployError("E0802", f"the build of '{program.modelname}' is not at '{built}'; "
                                   "compile it first")
    if not built.is_dir():
        raise DeployError("E0802", f"the build of '{program.modelname}' at '{built}' is not a folder")
    remote = settings.remote_of(program.modelname)
    if remote is None:
        raise DeployError("E0802", f"no repository to deploy '{program.modelname}' to: the pipeline "
                          "has no remote_base (or give --remote)")
    names.check_address(remote, "the model repository's address")
    names.check_folder_name(program.modelname)
    names.check_remote_name(settings.remote_name)
    for what, branch in (("success branch", settings.success_branch),
                         ("failure branch", settings.failure_branch),
                         ("production branch", settings.production_branch),
                         ("mesh branch", settings.mesh_branch), ("feature branch", settings.feature_branch)):
        if branch is not None:
            names.check_branch(branch, what)
    return remote


def _workdir(folder: Path) -> Path:
    """The workdir, made when missing (E0841 when it cannot be)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise DeployError("E0841", f"cannot use the workdir '{folder}': {e.strerror}") from None
    return folder.resolve()


def _deploy(program: Program, built: Path, remote: str, workdir: Path, settings: DeploySettings,
            result: DeployResult, tests: TestOutcome, pictures: Path | None = None,
            review: Review | None = None) -> None:
    clone = open_clone(remote, workdir / program.modelname, settings.remote_name)
    plan = make_plan(program, settings, clone.url, clone.default_branch, tests.failed)
    check_plan_branches(plan)
    result.branch = plan.branch
    protocol = tests.markdown
    prov = provenance(program, settings.definition_repo, tests)
    message = commit_message(program, prov)

    pinned = [submodules.pin(s, clone.url, plan.base, workdir) for s in plan.submodules]
    if settings.central_meshes and settings.meshes:
        from mpc.deploy.meshes import deploy_meshes

        mesh_pins = deploy_meshes(built, program.modelname, settings, plan, message, workdir)
        result.meshes = {p.target: p.sha for p in mesh_pins}
        pinned += mesh_pins

    forge = adapter(settings.forge, settings.github_api)
    request, reviewed = None, None
    if plan.mr_target is not None and forge.name != "none":
        changes = ""
        if review is not None:
            changes, reviewed = release_review(review, clone, plan.mr_target, workdir, program.modelname)
        described = "\n\n".join(part.strip() for part in (changes, protocol or "") if part.strip())
        request = merge_request(clone.url, plan.branch, plan.mr_target, plan.mr_title, plan.mr_description,
                                plan.mr_mention, described, footer(prov))

    def fill(c: Clone) -> None:
        fill_model(c, built, program, plan, prov, pinned)
        if pictures is not None and pictures.is_dir() and pictures.resolve() != built / FOLDER:
            copy_pictures(pictures, c.folder)
            c.git("add", "-A")
        if reviewed is not None and reviewed.is_dir():  # the review's, beside the protocol's
            copy_pictures(reviewed, c.folder, replace=False)
            c.git("add", "-A")

    published = publish(clone, plan.branch, plan.base, fill, message, settings.dry_run, forge, request)
    record_push(result, published, forge, request)
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
        path = content.safe_path(folder, target)
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
        content.safe_path(folder, target).mkdir(parents=True, exist_ok=True)
    clone.git("add", "-A")
    submodules.link(clone.git, pinned)


def _under(paths: set[str], folders: set[str]) -> set[str]:
    return {p for p in paths if any(p == f or p.startswith(f + "/") for f in folders)}

