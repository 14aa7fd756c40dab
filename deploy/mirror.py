"""`deployment.mirror`: a copy of the model repository's tree in a second repository, on
`mirror.branch`, with submodules kept as submodules (absolute addresses, since relative
ones would point into the mirror's namespace) or replaced by their files.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from mpc.deploy import content, lfs, submodules
from mpc.deploy.forges import adapter
from mpc.deploy.gitcmd import scrub, without_credentials
from mpc.deploy.merge_request import merge_request
from mpc.deploy.names import check_address
from mpc.deploy.plan import Plan
from mpc.deploy.provenance import Provenance, footer
from mpc.deploy.repository import Clone, open_clone, publish
from mpc.deploy.result import DeployResult, record_push
from mpc.deploy.settings import DeploySettings


def deploy_mirror(source: Clone, plan: Plan, pinned: list[submodules.Pinned], settings: DeploySettings,
                  message: str, protocol: str | None, prov: Provenance, workdir: Path) -> DeployResult:
    """Copy the model repository's tree (as just deployed) to the mirror and push it."""
    mirror = plan.mirror
    assert mirror is not None
    check_address(mirror.repo, "the mirror's address")
    result = DeployResult(plan.modelname, remote=scrub(mirror.repo), branch=mirror.branch)
    clone = open_clone(mirror.repo, workdir / ".mirrors" / plan.modelname, settings.remote_name)
    targets = {p.target for p in pinned}
    # absolute addresses, without the credentials the model repository's address may carry
    absolute = [replace(p, url=without_credentials(p.fetched_from)) for p in pinned]

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
        request = merge_request(clone.url, mirror.branch, target, mirror.mr_title or plan.mr_title,
                                plan.mr_description, mention, protocol, footer(prov))
    published = publish(clone, mirror.branch, clone.default_branch, fill, message, settings.dry_run,
                        forge, request)
    record_push(result, published, forge, request)
    return result
