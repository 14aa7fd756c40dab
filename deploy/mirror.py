"""`deployment.mirror`: a copy of the model repository's tree in a second repository, on
`mirror.branch`, with submodules kept as submodules (absolute addresses, since relative
ones would point into the mirror's namespace) or replaced by their files.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.deploy import content, lfs, submodules
from mpc.deploy.forges import MergeRequest, adapter, describe
from mpc.deploy.plan import Plan
from mpc.deploy.provenance import Provenance, footer
from mpc.deploy.repository import Clone, open_clone, publish
from mpc.deploy.settings import DeploySettings

if TYPE_CHECKING:
    from mpc.deploy.model import DeployResult


def deploy_mirror(source: Clone, plan: Plan, pinned: list[submodules.Pinned], settings: DeploySettings,
                  message: str, protocol: str | None, prov: Provenance, workdir: Path) -> DeployResult:
    """Copy the model repository's tree (as just deployed) to the mirror and push it."""
    from mpc.deploy.model import DeployResult

    mirror = plan.mirror
    assert mirror is not None
    result = DeployResult(plan.modelname, remote=mirror.repo, branch=mirror.branch)
    clone = open_clone(mirror.repo, workdir / ".mirrors" / plan.modelname, settings.remote_name)
    targets = {p.target for p in pinned}
    absolute = [replace(p, url=p.fetched_from) for p in pinned]

    def fill(c: Clone) -> None:
        content.replace_content(c.folder, source.folder, set(), targets if mirror.submodules else set())
        (c.folder / ".gitmodules").unlink(missing_ok=True)
        lfs.track(c.git, plan.lfs_patterns)  # the copied .gitattributes needs LFS in this clone too
        if mirror.submodules:
            for target in targets:
                (c.folder / target).mkdir(parents=True, exist_ok=True)
            c.git("add", "-A")
            submodules.link(c.git, absolute)
        else:
            for p in pinned:
                submodules.write_files(p, c.folder / p.target)
            c.git("add", "-A")

    forge = adapter(settings.forge, settings.github_api)
    request = None
    target = mirror.mr_target or clone.default_branch
    if mirror.merge_request and target != mirror.branch and forge.name != "none":
        mention = mirror.mr_mention if mirror.mr_mention is not None else plan.mr_mention
        request = MergeRequest(clone.url, mirror.branch, target, mirror.mr_title or plan.mr_title,
                               describe(plan.mr_description, mention, protocol, footer(prov)), mention)
    options = forge.push_options(request) if request else []
    published = publish(clone, mirror.branch, clone.default_branch, fill, message, options, settings.dry_run)
    result.commit, result.pushed, result.diffstat = published.sha, published.pushed, published.diffstat
    if published.pushed and request is not None:
        result.push_options, result.merge_request = tuple(options), request
        result.merge_request_url = forge.after_push(request, published.output)
    return result
