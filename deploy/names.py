"""Names a deployment gives git and the file system, checked before anything is cloned or
pushed: branch names (`git check-ref-format --branch`, which also refuses a leading `-`),
repository addresses (never taken for an option) and the modelname (one folder of the workdir).
"""

from __future__ import annotations

import re

from mpc.core import gitrun
from mpc.deploy.gitcmd import DeployError


def check_branch(name: str, what: str) -> None:
    """Raise E0840 unless git accepts `name` as a branch name; `what` says where it came from."""
    if name and not name.startswith("-") and name != "HEAD" and name.isprintable():
        status, out, _ = gitrun.result(["check-ref-format", "--branch", name])
        if status == 0 and out.strip() == name:
            return
    raise DeployError("E0840", f"{what} '{name}' is not a valid git branch name")


def check_remote_name(name: str) -> None:
    """Raise E0840 for a remote name (GIT_REMOTE_NAME) git would not take, or take for an option."""
    if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]*", name) or name.endswith((".", ".lock")):
        raise DeployError("E0840", f"remote name '{name}' (GIT_REMOTE_NAME) is not a valid git remote name")


def check_address(url: str, what: str) -> None:
    """Raise E0802 for an address git would read as an option (`--upload-pack=…`)."""
    if not url.strip() or url.startswith("-"):
        raise DeployError("E0802", f"{what} '{url}' is not a repository address")


def check_folder_name(modelname: str) -> None:
    """Raise E0842 unless `modelname` can name a folder of its own in the workdir."""
    if modelname in (".", "..") or modelname.startswith(".") or any(c in modelname for c in "/\\\0"):
        raise DeployError("E0842", f"modelname '{modelname}' cannot name mpc's clone of its repository "
                                   "(a folder of the workdir): use no '/', '\\' nor leading '.'")

