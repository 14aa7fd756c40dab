"""DeployResult: what deploying one model (or its mirror) did, for the command line and the
pipeline's status.json. Addresses in it are shown ones: without credentials."""

from __future__ import annotations

from dataclasses import field

from mpc.core.record import record
from mpc.deploy.forges import ForgeAdapter
from mpc.deploy.gitcmd import scrub
from mpc.deploy.merge_request import MergeRequest
from mpc.deploy.repository import Published


@record(frozen=False)
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


def record_push(result: DeployResult, published: Published, forge: ForgeAdapter,
                request: MergeRequest | None) -> None:
    """What `publish` did, into `result`; the merge request is made once the push went through."""
    result.commit, result.pushed, result.diffstat = published.sha, published.pushed, published.diffstat
    request = published.request or request
    if published.pushed and request is not None:
        result.push_options = tuple(forge.push_options(request))
        result.merge_request = request
        url = forge.after_push(request, published.output)
        result.merge_request_url = scrub(url) if url else None
