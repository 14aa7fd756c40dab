"""Merge requests: one small adapter per forge, chosen by the pipeline's `forge`.

- `gitlab`: git push options (`merge_request.create`, `.target`, `.title`, `.description`,
  `.assign`), so it needs nothing but git; a server that does not advertise push options
  refuses the push, which is reported.
- `github`: the REST API (deploy/github.py), after the push.
- `none`: no merge request; the branch is pushed and that is all.
"""

from __future__ import annotations

import re
from typing import Protocol

from mpc.deploy.merge_request import MergeRequest

# A push option travels as one pkt-line (at most 65516 bytes); keep well below.
MAX_OPTION_BYTES = 60000
_GITLAB_MR_URL = re.compile(r"remote:\s+(https?://\S+/merge_requests/\d+)")


class ForgeAdapter(Protocol):
    """How a forge is told about a merge request: options on the push, a check before it
    (raising DeployError leaves the remote untouched), a call after it."""

    name: str

    def push_options(self, request: MergeRequest) -> list[str]: ...

    def before_push(self, request: MergeRequest) -> None: ...

    def after_push(self, request: MergeRequest, push_output: str) -> str | None: ...


class NoForge:
    """`forge: none`: branches only."""

    name = "none"

    def push_options(self, request: MergeRequest) -> list[str]:
        return []

    def before_push(self, request: MergeRequest) -> None:
        pass

    def after_push(self, request: MergeRequest, push_output: str) -> str | None:
        return None


class GitLab(NoForge):
    """GitLab's push options. A push option is one line, so the description's newlines
    become `<br/>` (GitLab renders it as Markdown); it is cut at MAX_OPTION_BYTES."""

    name = "gitlab"

    def push_options(self, request: MergeRequest) -> list[str]:
        description = request.description.rstrip("\n").replace("\r\n", "\n").replace("\n", "<br/>")
        encoded = description.encode()
        if len(encoded) > MAX_OPTION_BYTES:
            description = encoded[:MAX_OPTION_BYTES].decode(errors="ignore") + "… (cut)"
        options = ["merge_request.create", f"merge_request.target={request.target}",
                   f"merge_request.title={_one_line(request.title)}",
                   f"merge_request.description={description}"]
        options += [f"merge_request.assign={_one_line(user.lstrip('@'))}" for user in request.mention]
        return options

    def after_push(self, request: MergeRequest, push_output: str) -> str | None:
        found = _GITLAB_MR_URL.search(push_output)
        return found.group(1) if found else None


def _one_line(text: str) -> str:
    return " ".join(text.replace("\0", "").split())


def adapter(name: str, github_api: str) -> ForgeAdapter:
    """The adapter of a forge by its name in pipeline.yml."""
    if name == "gitlab":
        return GitLab()
    if name == "github":
        from mpc.deploy.github import GitHub

        return GitHub(github_api)
    return NoForge()
