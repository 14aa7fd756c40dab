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

from mpc.deploy.gitcmd import DeployError
from mpc.deploy.merge_request import MergeRequest

TOKEN_VARIABLES = ("GITHUB_TOKEN", "GH_TOKEN")
TIMEOUT = 30


def repository_slug(remote: str) -> str | None:
    """`owner/name` of a remote address, or None."""
    path = re.sub(r"^[a-zA-Z][a-zA-Z0-9+.-]*://[^/]*", "", remote)  # scheme://host
    path = re.sub(r"^[^/:]+@[^:/]+:", "", path)                       # user@host:
    parts = [p for p in path.removesuffix("/").removesuffix(".git").split("/") if p]
    return "/".join(parts[-2:]) if len(parts) >= 2 else None


def _timeout() -> float:
    """Seconds to wait for an answer: MPC_GITHUB_TIMEOUT, else TIMEOUT."""
    try:
        return max(0.1, float(os.environ.get("MPC_GITHUB_TIMEOUT", TIMEOUT)))
    except ValueError:
        return TIMEOUT


class GitHub:
    """A pull request per pushed branch. `before_push` finds the open pull request (which
    checks the token, the repository and the API's address before anything is pushed);
    `after_push` updates it, or creates one, and assigns the mentioned users."""

    name = "github"

    def __init__(self, api: str) -> None:
        self.api = api.rstrip("/")
        self._open: dict[MergeRequest, int | None] = {}

    def push_options(self, request: MergeRequest) -> list[str]:
        return []

    def before_push(self, request: MergeRequest) -> None:
        self._open[request] = self._find_open(request)

    def after_push(self, request: MergeRequest, push_output: str) -> str | None:
        number = self._open[request] if request in self._open else self._find_open(request)
        slug = self._slug(request)
        fields = {"title": request.title, "body": request.description}
        if number is not None:
            pull = self._call("PATCH", f"/repos/{slug}/pulls/{number}", fields)
        else:
            pull = self._call("POST", f"/repos/{slug}/pulls",
                              {**fields, "head": request.source, "base": request.target})
        number = _number(pull, "POST" if number is None else "PATCH", slug)
        users = [m.lstrip("@") for m in request.mention]
        if users:
            self._call("POST", f"/repos/{slug}/issues/{number}/assignees", {"assignees": users})
        url = pull.get("html_url")
        return url if isinstance(url, str) and url else None

    def comment(self, slug: str, number: int, body: str) -> str | None:
        """Post `body` as a comment on pull request `number` of `owner/name`; its address."""
        answer = self._call("POST", f"/repos/{slug}/issues/{number}/comments", {"body": body})
        url = answer.get("html_url") if isinstance(answer, dict) else None
        return url if isinstance(url, str) and url else None

    def _find_open(self, request: MergeRequest) -> int | None:
        """The number of the open pull request from the branch into the target, if any."""
        slug = self._slug(request)
        owner = slug.split("/")[0]
        query = urllib.parse.urlencode({"head": f"{owner}:{request.source}", "base": request.target,
                                        "state": "open"})
        found = self._call("GET", f"/repos/{slug}/pulls?{query}")
        if not isinstance(found, list):
            raise DeployError("E0805", f"GitHub answered GET /repos/{slug}/pulls with something that "
                                       "is not a list of pull requests")
        return _number(found[0], "GET", slug) if found else None

    @staticmethod
    def _slug(request: MergeRequest) -> str:
        slug = repository_slug(request.remote)
        if slug is None:
            raise DeployError("E0806", "cannot tell the GitHub repository (owner/name) of "
                                       f"'{request.remote}'")
        return slug

    @staticmethod
    def _token() -> str:
        token = next((os.environ[v] for v in TOKEN_VARIABLES if os.environ.get(v)), None)
        if token is None:
            raise DeployError("E0806", "forge 'github' needs a token in GITHUB_TOKEN (or GH_TOKEN) "
                                       "to open the pull request; nothing was pushed")
        return token

    def _call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(f"{self.api}{path}", data=data, method=method, headers={
            "Accept": "application/vnd.github+json", "X-GitHub-Api-Version": "2022-11-28",
            "Authorization": f"Bearer {self._token()}", "User-Agent": "mpc",
            **({"Content-Type": "application/json"} if data is not None else {})})
        where = f"{method} {path.split('?')[0]}"
        try:
            with urllib.request.urlopen(request, timeout=_timeout()) as response:
                raw = response.read()
        except urllib.error.HTTPError as e:
            raise DeployError("E0805", f"GitHub refused {where}: {e.code} {e.reason}{_message(e)}") from None
        except (urllib.error.URLError, OSError, ValueError) as e:
            reason = getattr(e, "reason", e)
            said = "timed out" if isinstance(reason, TimeoutError) else reason
            raise DeployError("E0805", f"cannot reach GitHub's API at {self.api} ({where}): {said}") from None
        try:
            return json.loads(raw or b"null")
        except ValueError:
            raise DeployError("E0805", f"GitHub answered {where} with something that is not JSON") from None


def _number(pull: Any, method: str, slug: str) -> int:
    """The number of a pull request GitHub described."""
    number = pull.get("number") if isinstance(pull, dict) else None
    if not isinstance(number, int) or isinstance(number, bool):
        raise DeployError("E0805", f"GitHub answered {method} /repos/{slug}/pulls without a pull "
                                   "request number")
    return number


def _message(error: urllib.error.HTTPError) -> str:
    """GitHub's own explanation of a refusal (`message`, `errors`), or nothing."""
    try:
        body = json.loads(error.read())
    except (ValueError, OSError):
        return ""
    if not isinstance(body, dict):
        return ""
    listed = body.get("errors")
    errors = "; ".join(str(e.get("message", e)) if isinstance(e, dict) else str(e)
                       for e in (listed if isinstance(listed, list) else []))
    return f": {body.get('message', '')}" + (f" ({errors})" if errors else "")
