"""A merge request: what a forge adapter (deploy/forges.py, deploy/github.py) is asked to open,
and its description. No git and no network here.
"""

from __future__ import annotations

from mpc.core.record import record
from mpc.deploy.gitcmd import scrub


@record
class MergeRequest:
    """A merge request from `source` into `target` of the repository at `remote`."""

    remote: str
    source: str
    target: str
    title: str
    description: str
    mention: tuple[str, ...]


def merge_request(remote: str, source: str, target: str, title: str, text: str, mention: tuple[str, ...],
                  protocol: str | None, footer: str) -> MergeRequest:
    """The request from `source` into `target`, its description made by `describe`; the title
    without credentials too."""
    return MergeRequest(remote, source, target, scrub(title), describe(text, mention, protocol, footer),
                        mention)


def describe(text: str, mention: tuple[str, ...], protocol: str | None, footer: str) -> str:
    """The description: the definition's text, the mentions, the test protocol, the footer;
    without credentials, should the protocol quote an address or a token."""
    parts = [text.strip()]
    if mention:
        parts.append(" ".join(mention))
    if protocol and protocol.strip():
        parts.append(protocol.strip())
    parts.append(footer)
    return scrub("\n\n".join(parts) + "\n").replace("\0", "")
