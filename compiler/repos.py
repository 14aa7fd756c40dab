"""Git repositories that input models come from: cloned once into a cache, checked out at
exactly the commit (or branch) a definition names.

Cache: `$MPC_CACHE_DIR/repos`, else `$XDG_CACHE_HOME/mpc/repos`, else `~/.cache/mpc/repos`;
one folder per URL (without credentials) and commit, so two definitions at different commits never disturb
each other and a pinned commit is cloned once. A branch is fetched on every use and
resolved to its current commit.

Whoever can write the cache can write the mirror's config, and git runs what a config tells
it to (a URL rewritten to `ext::<command>`, `core.sshCommand`, a hook). Before each fetch the
mirror's config is read as a plain file: one holding anything but what `git clone --bare`
and `git remote set-url` write is not mpc's, and the mirror is cloned anew (W0650); no hook
of the mirror runs (`core.hooksPath` is /dev/null for each git run in it).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
from pathlib import Path

from mpc.core.cache import cache_dir
from mpc.core.diagnostics import Sink
from mpc.core.files import describe
from mpc.core.gitrun import GitFailed, git, scrub, without_credentials
from mpc.core.reads import note_volatile
from mpc.core.span import Span
from mpc.ir.program import RepoRef


def _slot(url: str) -> Path:
    # keyed without credentials: a CI token changes from job to job, the repository does not
    return cache_dir("repos") / hashlib.sha256(without_credentials(url).encode()).hexdigest()[:16]


# What `git clone --bare` and `git remote set-url` write into a mirror's config (on any
# platform); anything else was written by someone else.
_MIRROR_KEYS = frozenset({
    "core.repositoryformatversion", "core.filemode", "core.bare", "core.ignorecase",
    "core.precomposeunicode", "core.symlinks", "core.logallrefupdates", "remote.origin.url",
    "extensions.objectformat"})
_NO_HOOKS = ("-c", "core.hooksPath=/dev/null")


def checkout(repo: RepoRef, sink: Sink, span: Span, fetch: bool = True) -> Path | None:
    """The work tree of `repo` at its commit (or branch); None after reporting why.

    fetch: False for `mpc check`, which only uses what is cached already (None otherwise).
    """
    ref = repo.commit or repo.branch or "HEAD"
    slot = _slot(repo.git)
    if not repo.commit:  # what a branch holds changes without any file here changing
        note_volatile(f"the branch '{ref}' of repository '{scrub(repo.git)}'")
    try:
        if repo.commit and (slot / repo.commit).is_dir():
            return slot / repo.commit
        if not fetch:
            return None
        return _checkout(repo, ref, slot, sink, span)
    except GitFailed as e:
        sink.error(span, "E0604", f"cannot get '{ref}' of repository '{scrub(repo.git)}': {e.message}")
    except OSError as e:
        sink.error(span, "E0604", f"cannot get '{ref}' of repository '{scrub(repo.git)}': "
                   f"{describe(e, 'keep the checkout')}")
    return None


def _checkout(repo: RepoRef, ref: str, slot: Path, sink: Sink, span: Span) -> Path:
    """Fetch into the slot's mirror and check `ref` out into its own folder; raises
    GitFailed or OSError."""
    slot.mkdir(parents=True, exist_ok=True)
    mirror = slot / "mirror.git"
    if mirror.is_dir() or mirror.is_symlink():
        strange = _not_mpcs(mirror)
        if strange is not None:
            sink.warning(span, "W0650", f"the cache's clone '{mirror}' of repository '{scrub(repo.git)}' is "
                         f"unusable ({strange}); it is removed and cloned again")
            if mirror.is_symlink() or not mirror.is_dir():
                mirror.unlink()
            else:
                shutil.rmtree(mirror)
    if mirror.is_dir():
        git(*_NO_HOOKS, "fetch", "--quiet", repo.git, "+refs/heads/*:refs/heads/*", cwd=mirror)
    else:
        git(*_NO_HOOKS, "clone", "--quiet", "--bare", "--", repo.git, str(mirror))
        # no token in the cache's config: fetches name the URL of the day
        git(*_NO_HOOKS, "remote", "set-url", "origin", without_credentials(repo.git), cwd=mirror)
    sha = git(*_NO_HOOKS, "rev-parse", "--verify", "--end-of-options", f"{ref}^{{commit}}", cwd=mirror)
    tree = slot / sha
    if not tree.is_dir():
        staging = Path(tempfile.mkdtemp(prefix=".checkout-", dir=slot))
        try:
            git("clone", "--quiet", "--no-checkout", "--", str(mirror), str(staging))
            git("checkout", "--quiet", sha, cwd=staging)
            shutil.rmtree(staging / ".git", ignore_errors=True)
            os.replace(staging, tree)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    if repo.commit and repo.commit != sha and not (slot / repo.commit).exists():
        (slot / repo.commit).symlink_to(sha)  # an abbreviated commit finds the tree next time
    return tree


def _not_mpcs(mirror: Path) -> str | None:
    """Why the mirror is not one mpc made (a link, a config key git would act on), or None.
    The config is read as a file (`--file`: no includes followed), nothing run from it."""
    if mirror.is_symlink():
        return "it is a link"
    try:
        listed = git("config", "--file", str(mirror / "config"), "--null", "--name-only", "--list")
    except GitFailed as e:
        return f"its config cannot be read: {e.message}"
    keys = {k.lower() for k in listed.split("\0") if k}
    strange = sorted(keys - {k.lower() for k in _MIRROR_KEYS})
    return f"its config sets '{strange[0]}'" if strange else None
