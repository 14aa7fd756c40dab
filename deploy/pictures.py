"""The test protocol's pictures in a deployment: copied into the commit (`test_pictures/`),
and their relative links in the merge request's description rewritten to the forge's raw
address of the pushed commit, so that GitLab's and GitHub's review pages show them.

It links only the files mpc wrote (`test_pictures/<name>.png`, the kinematic tree's `.pdf`);
other links of the description stay as they are. It knows GitHub's (`/raw/<sha>/…`) and GitLab's
(`/-/raw/<sha>/…`) addresses; a remote without a web host (a path, file://) keeps the links
relative, and the description says where the pictures are.
"""

from __future__ import annotations

import re
import shutil
from dataclasses import replace
from pathlib import Path

from mpc.deploy.forges import MergeRequest
from mpc.deploy.gitcmd import DeployError

FOLDER = "test_pictures"  # as checks/pictures.py writes it, beside the protocol
_LINK = re.compile(r"\]\((" + FOLDER + r"/[A-Za-z0-9_.-]+\.(?:png|pdf))\)")
_PICTURE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*\.(?:png|pdf)")


def web_address(remote: str) -> str | None:
    """`https://host/group/name` of a remote address (https, ssh, scp-like `git@host:path`),
    without credentials, port or `.git`; None for a path or file:// address."""
    m = re.fullmatch(r"(?:https?|ssh|git)://(?:[^@/]*@)?([^/:]+)(?::\d+)?/(.+)", remote) or \
        re.fullmatch(r"[^@/:]+@([^:/]+):(?!/)(.+)", remote)
    if m is None:
        return None
    path = m.group(2).strip("/").removesuffix(".git")
    return f"https://{m.group(1)}/{path}" if path else None


def raw_base(forge: str, remote: str, sha: str) -> str | None:
    """The address under which the forge serves the files of commit `sha`, ending in `/`."""
    web = web_address(remote)
    if web is None:
        return None
    return f"{web}/raw/{sha}/" if forge == "github" else f"{web}/-/raw/{sha}/"


def link_pictures(request: MergeRequest, forge: str, sha: str) -> MergeRequest:
    """The request with its pictures' links pointing at commit `sha` on the forge."""
    if not _LINK.search(request.description):
        return request
    base = raw_base(forge, request.remote, sha)
    if base is None:
        note = (f"\n(The pictures are in the commit's `{FOLDER}/`; the repository's address names no "
                "web host to link them.)\n")
        return replace(request, description=request.description + note)
    return replace(request, description=_LINK.sub(lambda m: f"]({base}{m.group(1)})", request.description))


def copy_pictures(source: Path, clone: Path, replace: bool = True) -> None:
    """The PNG and PDF files of `source` (the folder beside the protocol) into `clone/test_pictures/`,
    replacing what was there (with `replace`: else beside it). Only regular files named like
    mpc's pictures are taken; a symbolic link is E0850 (it could publish any file of the machine)."""
    target = clone / FOLDER
    if target.is_symlink() or target.is_file():
        target.unlink()
    elif target.exists() and replace:
        shutil.rmtree(target)
    target.mkdir(exist_ok=True)
    for path in sorted(source.iterdir()):
        if path.is_symlink():
            raise DeployError("E0850", f"the test picture '{path}' is a symbolic link; mpc deploys "
                                       "the pictures mpc test wrote, as files")
        if path.is_file() and _PICTURE.fullmatch(path.name):
            shutil.copyfile(path, target / path.name)
