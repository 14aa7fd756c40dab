"""One repository's update: clone or fetch, start from the remote branch, fill the tree,
commit, push — never forced, never deleting a branch.

`publish` runs the whole round. When the push is refused because the remote branch moved
after the fetch, it fetches again and rebuilds the commit on top of the new remote branch
(filling the tree again), a few times at most; any other refusal is an error. A dry run
stops before the commit and returns the diff stat the push would carry.
"""

from __future__ import annotations

import fcntl
import hashlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from mpc.core.record import record
from mpc.deploy.forges import ForgeAdapter
from mpc.deploy.gitcmd import EMPTY_TREE, DeployError, Git, without_credentials
from mpc.deploy.merge_request import MergeRequest
from mpc.deploy.pictures import link_pictures

ATTEMPTS = 3


@record(frozen=False)
class Clone:
    """mpc's clone of a repository. default_branch: the remote's HEAD branch."""

    folder: Path
    git: Git
    remote: str
    url: str
    default_branch: str

    def remote_sha(self, branch: str) -> str | None:
        """The commit of `branch` on the remote, as last fetched; None if it has no such branch."""
        ref = f"refs/remotes/{self.remote}/{branch}"
        if not self.git.ok("rev-parse", "--verify", "-q", ref):
            return None
        return self.git("rev-parse", "--verify", "-q", ref)

    def fetch(self) -> None:
        self.git("fetch", "-q", "--prune", self.remote)


@contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold `<folder>.lock` exclusively: models deployed in parallel share the central mesh
    repositories and submodule caches, whose clones one process at a time may use."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    with open(folder.with_name(folder.name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def folder_for(parent: Path, url: str) -> Path:
    """A folder of `parent` named by a repository's address (without credentials, so that a CI
    job's new token finds the same folder); no address leads out of `parent`."""
    return parent / hashlib.sha256(without_credentials(url).encode()).hexdigest()[:16]


def open_clone(url: str, folder: Path, remote: str = "origin") -> Clone:
    """A clone of `url` in `folder`, fetched now; cloned when the folder does not exist.
    The caller holds the folder's lock (`locked`), so a `.git/index.lock` left there is the
    leftover of a run that was stopped, and goes."""
    existed = folder.exists()
    if existed:
        if not (folder / ".git").is_dir():
            raise DeployError("E0803", f"'{folder}' exists and is not a git clone; mpc clones into "
                                       "folders of its own (remove it or choose another workdir)")
        (folder / ".git" / "index.lock").unlink(missing_ok=True)
        git = Git(folder)
        current = git("config", "--get", f"remote.{remote}.url", check=False)  # as written, no insteadOf
        if without_credentials(current) != without_credentials(url):
            raise DeployError("E0803", f"'{folder}' is a clone of '{current or 'nothing'}', not of '{url}'")
        if current != url:  # the same repository with new credentials (CI tokens change every job)
            git("remote", "set-url", remote, url)
    else:
        folder.parent.mkdir(parents=True, exist_ok=True)
        Git(folder.parent)("clone", "-q", "--no-checkout", "--origin", remote, "--", url, str(folder))
        git = Git(folder)
    clone = Clone(folder, git, remote, url, "")
    if existed:
        clone.fetch()
    clone.default_branch = _default_branch(git, remote)
    return clone


def _default_branch(git: Git, remote: str) -> str:
    """The remote's HEAD branch, asked of the remote on every run: never the clone's own
    HEAD, which names whatever branch the last run (a failed one, say) checked out."""
    listing = git("ls-remote", "--symref", remote, "HEAD", check=False)
    for line in listing.splitlines():
        if line.startswith("ref: refs/heads/") and line.endswith("\tHEAD"):
            return line[len("ref: refs/heads/"):-len("\tHEAD")]
    return _unborn_head(git, remote)


def _unborn_head(git: Git, remote: str) -> str:
    """The branch an empty remote's HEAD names (or a remote whose HEAD branch has no commit
    yet, while other branches have): `ls-remote` does not show it, but a clone gets it. The
    clone follows HEAD alone, so it fetches nothing; it goes into a scratch folder of the
    clone's `.git`. `master` when even that fails."""
    import tempfile

    url = git("remote", "get-url", remote, check=False)
    scratch = git.folder / ".git" / "mpc-probe"
    scratch.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory(dir=scratch) as folder:
        probe = Git(Path(folder) / "head")
        status, _, _ = Git(Path(folder)).result("clone", "-q", "--bare", "--no-local", "--single-branch",
                                                "--no-tags", "--depth", "1", "--", url, str(probe.folder))
        head = probe("symbolic-ref", "-q", "HEAD", check=False) if status == 0 else ""
    return head.removeprefix("refs/heads/") if head.startswith("refs/heads/") else "master"


def start_branch(clone: Clone, branch: str, base: str | None) -> str | None:
    """Check out `branch` as the remote has it; a new branch starts at the remote's `base`,
    or empty. Leftovers of earlier runs are cleaned. The commit it starts at, or None."""
    git = clone.git
    start = clone.remote_sha(branch) or (clone.remote_sha(base) if base else None)
    if start is not None:
        git("checkout", "-q", "-f", "-B", branch, start)
    else:  # an empty remote, or neither branch exists: an orphan branch
        git("symbolic-ref", "HEAD", f"refs/heads/{branch}")
        if git.ok("rev-parse", "--verify", "-q", f"refs/heads/{branch}"):
            git("update-ref", "-d", f"refs/heads/{branch}")  # a local leftover, never pushed
        git("read-tree", "--empty")
    git("clean", "-q", "-ffdx")
    return start


def staged_changes(git: Git, start: str | None) -> bool:
    """Whether the index differs from the commit the branch starts at."""
    return not git.ok("diff", "--cached", "--quiet", start or EMPTY_TREE)


def diff_stat(git: Git, start: str | None) -> str:
    return git("diff", "--cached", "--stat", start or EMPTY_TREE)


def commit(git: Git, message: str) -> str:
    """Commit the index; the new commit. Without an identity from the environment or git's
    configuration, the commit is made as `mpc <mpc@localhost>`."""
    identity = [] if git.ok("var", "GIT_COMMITTER_IDENT") and git.ok("var", "GIT_AUTHOR_IDENT") \
        else ["-c", "user.name=mpc", "-c", "user.email=mpc@localhost"]
    git(*identity, "commit", "-q", "--no-gpg-sign", "-m", message)
    return git("rev-parse", "HEAD")


@record(frozen=False)
class Published:
    """What `publish` did. sha: the new commit (None: nothing to commit). output: the
    push's messages (a forge may print the merge request's address there)."""

    sha: str | None
    pushed: bool
    diffstat: str = ""
    output: str = ""
    attempts: int = 1
    request: MergeRequest | None = None  # as pushed: its pictures linked to the commit


Fill = Callable[[Clone], None]


def publish(clone: Clone, branch: str, base: str | None, fill: Fill, message: str, dry_run: bool,
            forge: ForgeAdapter | None = None, request: MergeRequest | None = None) -> Published:
    """Fill `branch` (from the remote's branch, or `base`) with `fill`, commit and push, with the
    forge's push options for `request`. The forge checks it can make the request before the
    push, so that a forge that refuses leaves the remote as it was.

    A branch that moved after the fetch is filled again from its new commit: the build wins
    for every file it writes, the remote's new commit for the files `keep_files` names, and
    files the other commit added that neither names are removed, as on every update.
    """
    options = forge.push_options(request) if forge is not None and request is not None else []
    original = request
    for attempt in range(1, ATTEMPTS + 1):
        start = start_branch(clone, branch, base)
        fill(clone)
        if not staged_changes(clone.git, start):
            return Published(None, False, attempts=attempt)
        if dry_run:
            return Published(None, False, diff_stat(clone.git, start), attempts=attempt)
        sha = commit(clone.git, message)
        if forge is not None and request is not None:
            # the description's pictures link to this commit (deploy/pictures.py)
            request = link_pictures(original, forge.name, sha)  # type: ignore[arg-type]
            options = forge.push_options(request)
        if forge is not None and request is not None and attempt == 1:
            forge.before_push(request)
        args = ["push", "--porcelain"]
        for option in options:
            args += ["-o", option]
        status, out, err = clone.git.result(*args, "--", clone.remote, f"HEAD:refs/heads/{branch}")
        if status == 0:
            return Published(sha, True, output=f"{out}\n{err}", attempts=attempt, request=request)
        before = clone.remote_sha(branch)
        clone.fetch()
        if clone.remote_sha(branch) == before:
            hint = ("\n(the server does not take git push options, which forge 'gitlab' uses for "
                    "merge requests: choose another forge)") if "does not support push options" in err else ""
            raise DeployError("E0803", f"pushing to branch '{branch}' of '{clone.url}' failed:\n"
                                       f"{(err or out).strip()}{hint}")
        # The branch moved between our fetch and our push: build the commit again on top of it.
    raise DeployError("E0803", f"branch '{branch}' of '{clone.url}' moved during each of {ATTEMPTS} "
                               "attempts to push; nothing was overwritten, try again later")
