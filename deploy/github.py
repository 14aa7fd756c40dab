"""GitHub pull requests through the REST API: create one for the pushed branch, or update
the open one (title and body), then assign the mentioned users.

The token comes from GITHUB_TOKEN (or GH_TOKEN) and goes only into the Authorization
header; messages never show it (gitcmd.scrub removes it anyway). The repository is the
last two parts of the remote's address (`owner/name`), which is what GitHub addresses
(`git@github.com:owner/name.git`, `https://github.com/owner/name`) contain.
"""

from __future__ import annotations

import json
import os
import re
import urllib.error
import urllib.parse
import urllib.request
from typing import Any

from mpc.deploy.forges import MergeRequest
from mpc.deploy.gitcmd import DeployError

TOKEN_VARIABLES = ("GITHUB_TOKEN", "GH_TOKEN")
TIMEOUT = 30


def repository_slug(remote: str) -> str | None:
    """`owner/name` of a remote address, or None."""
    path = re.sub(r"^[a-zA-Z][a-zA-Z0-9+.-]*://[^/]*", "", remote)  # scheme://host
    path = re.sub(r"^[^/:]+@[^:/]+:", "", path)                       # user@host:
    parts = [p for p in path.removesuffix("/").removesuffix(".git").split("/") if p]
    return "/".join(parts[-2:]) if len(parts) >= 2 else None


class GitHub:
    """A pull request per pushed branch."""

    name = "github"

    def __init__(self, api: str) -> None:
        self.api = api.rstrip("/")

    def push_options(self, request: MergeRequest) -> list[str]:
        return []

    def after_push(self, request: MergeRequest, push_output: str) -> str | None:
        token = next((os.environ[v] for v in TOKEN_VARIABLES if os.environ.get(v)), None)
        if token is None:
            raise DeployError("E0806", "forge 'github' needs a token in GITHUB_TOKEN (or GH_TOKEN) "
                                       "to open the pull request; the branch was pushed")
        slug = repository_slug(request.remote)
        if slug is None:
            raise DeployError("E0806", "cannot tell the GitHub repository (owner/name) of "
                                       f"'{request.remote}'")
        owner = slug.split("/")[0]
        query = urllib.parse.urlencode({"head": f"{owner}:{request.source}", "base": request.target,
                                        "state": "open"})
        found = self._call(token, "GET", f"/repos/{slug}/pulls?{query}")
        fields = {"title": request.title, "body": request.description}
        if found:
            pull = self._call(token, "PATCH", f"/repos/{slug}/pulls/{found[0]['number']}", fields)
        else:
            pull = self._call(token, "POST", f"/repos/{slug}/pulls",
                              {**fields, "head": request.source, "base": request.target})
        users = [m.lstrip("@") for m in request.mention]
        if users:
            self._call(token, "POST", f"/repos/{slug}/issues/{pull['number']}/assignees",
                       {"assignees": users})
        return str(pull.get("html_url") or "") or None

    def _call(self, token: str, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(f"{self.api}{path}", data=data, method=method, headers={
            "Accept": "application/vnd.github+json", "X-GitHub-Api-Version": "2022-11-28",
            "Authorization": f"Bearer {token}", "User-Agent": "mpc",
            **({"Content-Type": "application/json"} if data is not None else {})})
        try:
            with urllib.request.urlopen(request, timeout=TIMEOUT) as response:
                return json.loads(response.read() or b"null")
        except urllib.error.HTTPError as e:
            detail = _message(e.read())
            raise DeployError("E0805", f"GitHub refused {method} {path.split('?')[0]}: "
                                       f"{e.code} {e.reason}{detail}") from None
        except (urllib.error.URLError, OSError, ValueError) as e:
            raise DeployError("E0805", f"cannot reach GitHub's API at {self.api}: "
                                       f"{getattr(e, 'reason', e)}") from None


def _message(raw: bytes) -> str:
    try:
        body = json.loads(raw)
    except ValueError:
        return ""
    if not isinstance(body, dict):
        return ""
    errors = "; ".join(str(e.get("message", e)) if isinstance(e, dict) else str(e)
                       for e in body.get("errors", []))
    return f": {body.get('message', '')}" + (f" ({errors})" if errors else "")
