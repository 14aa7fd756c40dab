"""Git LFS tracking in a clone: `git lfs install --local` and `git lfs track` for the
patterns the plan names (deploy/plan.py); `.gitattributes` is then committed with the rest.
git-lfs comes from Debian (scripts/setup.sh)."""

from __future__ import annotations

import shutil

from mpc.deploy.gitcmd import DeployError, Git


def track(git: Git, patterns: tuple[str, ...]) -> None:
    """Track `patterns` with LFS in the clone (nothing when there are none)."""
    if not patterns:
        return
    if shutil.which("git-lfs") is None:
        raise DeployError("E0808", "the deployment uses git LFS, but git-lfs is not installed "
                                   "(apt-get install git-lfs)")
    if (git.folder / ".gitattributes").is_symlink():  # kept from the remote: never written through
        raise DeployError("E0804", "'.gitattributes' is a symbolic link; git LFS would write through it")
    git("lfs", "install", "--local", code="E0808")
    for pattern in patterns:  # one at a time: given several, git-lfs writes them in any order
        git("lfs", "track", pattern, code="E0808")
