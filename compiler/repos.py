"""Git repositories that input models come from: cloned once into a cache, checked out at
exactly the commit (or branch) a definition names.

Cache: `$MPC_CACHE_DIR/repos`, else `$XDG_CACHE_HOME/mpc/repos`, else `~/.cache/mpc/repos`;
one folder per URL and commit, so two definitions at different commits never disturb
each other and a pinned commit is cloned once. A branch is fetched on every use and
resolved to its current commit.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
from pathlib import Path

from mpc.compiler.cache import cache_dir
from mpc.compiler.diagnostics import Sink
from mpc.ir.program import RepoRef
from mpc.ir.span import Span


def _slot(url: str) -> Path:
    return cache_dir("repos") / hashlib.sha256(url.encode()).hexdigest()[:16]


def checkout(repo: RepoRef, sink: Sink, span: Span, fetch: bool = True) -> Path | None:
    """The work tree of `repo` at its commit (or branch); None after reporting why.

    fetch: False for `mpc check`, which only uses what is cached already (None otherwise).
    """
    import git  # GitPython: only needed when a definition names a repository

    ref = repo.commit or repo.branch or "HEAD"
    slot = _slot(repo.git)
    if repo.commit and (slot / repo.commit).is_dir():
        return slot / repo.commit
    if not fetch:
        return None
    slot.mkdir(parents=True, exist_ok=True)
    mirror = slot / "mirror.git"
    try:
        if mirror.is_dir():
            git.Repo(mirror).remote().fetch("+refs/heads/*:refs/heads/*", prune=False)
        else:
            git.Repo.clone_from(repo.git, mirror, bare=True)
        store = git.Repo(mirror)
        sha = store.commit(ref).hexsha
    except (git.GitCommandError, git.BadName, ValueError) as e:
        sink.error(span, "E0604", f"cannot get '{ref}' of repository '{repo.git}': "
                   f"{_first_line(e)}")
        return None
    tree = slot / sha
    if not tree.is_dir():
        staging = Path(tempfile.mkdtemp(prefix=".checkout-", dir=slot))
        try:
            git.Repo.clone_from(str(mirror), staging, no_checkout=True).git.checkout(sha)
            shutil.rmtree(staging / ".git", ignore_errors=True)
            os.replace(staging, tree)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    if repo.commit and repo.commit != sha and not (slot / repo.commit).exists():
        (slot / repo.commit).symlink_to(sha)  # an abbreviated commit finds the tree next time
    return tree


def _first_line(e: Exception) -> str:
    text = getattr(e, "stderr", "") or str(e)
    lines = [ln.strip() for ln in str(text).splitlines() if ln.strip()]
    return lines[-1].removeprefix("stderr: ").strip("'") if lines else type(e).__name__
