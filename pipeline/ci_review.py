"""`mpc ci review PIPELINE`: in a merge request's pipeline, the changes of every model against
the merge request's base (`mpc diff DEFINITION@BASE DEFINITION`, checks/diff_sides.py), posted
as one comment on the merge request. The generated pipelines run it in their summary job.

Where it runs is read from the CI's own variables: GitLab's `CI_MERGE_REQUEST_IID`,
`CI_MERGE_REQUEST_DIFF_BASE_SHA`, `CI_API_V4_URL` and `CI_MERGE_REQUEST_PROJECT_ID` (token:
`MPC_GITLAB_TOKEN`, else `GITLAB_TOKEN`, sent as PRIVATE-TOKEN); GitHub's pull_request event
(`GITHUB_EVENT_PATH`: its number and base commit; `GITHUB_REPOSITORY`, `GITHUB_API_URL`; token
`GITHUB_TOKEN`). Outside a merge request it does nothing (without `--base`). The Markdown is
printed too; a token never is.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import urllib.error
import urllib.request
from pathlib import Path

from mpc.core.record import record
from mpc.pipeline import dag
from mpc.pipeline.plan import Plan

MARK = "<!-- mpc ci review -->"  # the first line of the comment: what made it
GITLAB_TOKENS = ("MPC_GITLAB_TOKEN", "GITLAB_TOKEN")


@record
class Target:
    """The merge request to comment on: forge (gitlab, github), the API's address, the project
    (GitLab's id, GitHub's owner/name), the request's number and its base commit."""

    forge: str
    api: str
    project: str
    number: int
    base: str


def target_of(environ: dict[str, str]) -> Target | None:
    """The merge request this CI job runs for, or None."""
    if environ.get("CI_MERGE_REQUEST_IID", "").isdigit():
        return Target("gitlab", environ.get("CI_API_V4_URL", "").rstrip("/"),
                      environ.get("CI_MERGE_REQUEST_PROJECT_ID") or environ.get("CI_PROJECT_ID", ""),
                      int(environ["CI_MERGE_REQUEST_IID"]), environ.get("CI_MERGE_REQUEST_DIFF_BASE_SHA", ""))
    if environ.get("GITHUB_EVENT_NAME") in ("pull_request", "pull_request_target") and environ.get(
            "GITHUB_EVENT_PATH"):
        try:
            pull = json.loads(Path(environ["GITHUB_EVENT_PATH"]).read_text(encoding="utf-8"))["pull_request"]
            number, base = int(pull["number"]), str(pull["base"]["sha"])
        except (OSError, ValueError, KeyError, TypeError):
            return None
        return Target("github", environ.get("GITHUB_API_URL", "https://api.github.com").rstrip("/"),
                      environ.get("GITHUB_REPOSITORY", ""), number, base)
    return None


def changes(plan: Plan, base: str) -> str:
    """The Markdown of every model's changes from its definition at `base` to its definition now."""
    from mpc.checks.diff_models import diff
    from mpc.checks.diff_report import markdown
    from mpc.checks.diff_sides import BadSide, load_side
    from mpc.core.diagnostics import Sink
    from mpc.ir.program import Tolerances

    parts = [MARK]
    for name in dag.order(plan.parents()):
        model = plan.models[name]
        sink = Sink()
        with tempfile.TemporaryDirectory(prefix="mpc-review-") as work:
            try:
                old = load_side(f"{model.definition}@{base}", sink, Path(work))
                new = load_side(str(model.definition), sink, Path(work)) if old is not None else None
            except BadSide as e:
                old = new = None
                sink.error(model.span, "E0741", str(e))
            if old is None or new is None:
                why = next((d.message for d in sink.diagnostics if d.severity.name == "ERROR"), "")
                parts.append(f"## `{name}`\n\nNot compared with `{base[:12]}`: {why}\n")
                continue
            tol = Tolerances()
            parts.append(markdown(diff(old.robot, new.robot, tol), f"{model.written}@{base[:12]}",
                                  model.written, tol, title=f"Changes of `{name}`"))
    return "\n".join(parts)


def post(target: Target, body: str, environ: dict[str, str]) -> str:
    """Post the comment; where it went. Raises PostFailed with the forge's reason."""
    if target.forge == "github":
        from mpc.deploy.gitcmd import DeployError
        from mpc.deploy.github import GitHub

        try:
            url = GitHub(target.api).comment(target.project, target.number, body)
        except DeployError as e:
            raise PostFailed(e.message) from None
        return url or f"pull request #{target.number}"
    token = next((environ[v] for v in GITLAB_TOKENS if environ.get(v)), None)
    if token is None:
        raise PostFailed("no token to post with: set MPC_GITLAB_TOKEN (a project access token that "
                         "may write notes)")
    path = f"/projects/{target.project}/merge_requests/{target.number}/notes"
    request = urllib.request.Request(target.api + path, data=json.dumps({"body": body}).encode(),
                                     method="POST", headers={"PRIVATE-TOKEN": token,
                                                             "Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=30) as answer:
            answer.read()
    except urllib.error.HTTPError as e:
        raise PostFailed(f"GitLab refused POST {path}: {e.code} {e.reason}") from None
    except (urllib.error.URLError, OSError, ValueError) as e:
        raise PostFailed(f"cannot reach GitLab's API at {target.api}: {getattr(e, 'reason', e)}") from None
    return f"merge request !{target.number}"


class PostFailed(Exception):
    """The forge did not take the comment; the message says why (without the token)."""

    def __init__(self, message: str) -> None:
        from mpc.core.gitrun import scrub

        self.message = scrub(message)
        super().__init__(self.message)


def review(plan: Plan, base: str | None) -> int:
    """`mpc ci review` (see the module's docstring): 0 posted or nothing to do, 1 not posted."""
    environ = dict(os.environ)
    target = target_of(environ)
    base = base or (target.base if target is not None else None)
    if not base:
        print("mpc ci review: not in a merge request's pipeline (and no --base): nothing to review",
              file=sys.stderr)
        return 0
    body = changes(plan, base)
    print(body)
    if target is None:
        return 0
    try:
        where = post(target, body, environ)
    except PostFailed as e:
        print(f"mpc ci review: error: the review was not posted: {e.message}", file=sys.stderr)
        return 1
    print(f"posted the review to {where}", file=sys.stderr)
    return 0
