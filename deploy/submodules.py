"""`deployment.submodules` → gitlinks and `.gitmodules` entries in a clone, or (for a
mirror without submodules) the submodules' files themselves.

A submodule is fetched into a bare cache in the workdir to find its commit (the one given,
or the newest of its branch); the clone's index then gets the gitlink directly, so no
submodule is ever checked out inside the model repository.
"""

from __future__ import annotations

import tarfile
from pathlib import Path

from mpc.core.record import record
from mpc.deploy.gitcmd import DeployError, Git, without_credentials
from mpc.deploy.repository import folder_for, locked
from mpc.ir.program import DeploySubmodule


@record
class Pinned:
    """A submodule resolved: the url written into .gitmodules (as in the definition, without
    credentials), the url fetched from (absolute), its branch, its commit, its cache."""

    target: str
    url: str
    fetched_from: str
    branch: str
    sha: str
    cache: Path


def absolute_url(url: str, superproject: str) -> str:
    """A submodule address relative to the superproject's (`../x.git`, `./x`) made absolute,
    as git does: each `../` drops one part of the superproject's address."""
    if not url.startswith(("./", "../")):
        return url
    base = superproject.rstrip("/")
    rest = url
    while rest.startswith(("./", "../")):
        if rest.startswith("./"):
            rest = rest[2:]
            continue
        rest = rest[3:]
        cut = max(base.rfind("/"), base.rfind(":"))
        if cut < 0:
            raise DeployError("E0807", f"submodule address '{url}' goes above '{superproject}'")
        base = base[:cut] if base[cut] == "/" else base[:cut + 1]
    return f"{base}{'' if base.endswith(':') else '/'}{rest}"


def pin(sub: DeploySubmodule, superproject: str, default_branch: str, workdir: Path) -> Pinned:
    """Fetch the submodule and find its commit."""
    fetched_from = absolute_url(sub.repo, superproject)
    cache = folder_for(workdir / ".submodules", fetched_from)
    branch = sub.branch or default_branch
    with locked(cache):
        sha = _find(sub, fetched_from, branch, cache)
    return Pinned(sub.target, without_credentials(sub.repo), fetched_from, branch, sha, cache)


def _find(sub: DeploySubmodule, fetched_from: str, branch: str, cache: Path) -> str:
    """The submodule's commit, fetched into the bare `cache`."""
    if not cache.exists():
        cache.mkdir(parents=True)
        Git(cache)("init", "-q", "--bare", code="E0807")
    git = Git(cache)
    git("fetch", "-q", "--prune", "--", fetched_from, "+refs/heads/*:refs/heads/*", code="E0807")
    if sub.commit:
        ref = f"{sub.commit}^{{commit}}"
        what = f"commit '{sub.commit}'"
    else:
        ref = f"refs/heads/{branch}"
        what = f"branch '{branch}'"
    if not git.ok("rev-parse", "--verify", "-q", ref):
        raise DeployError("E0807", f"submodule '{sub.target}': '{fetched_from}' has no {what}")
    return git("rev-parse", ref)


def link(git: Git, pinned: list[Pinned]) -> None:
    """Write `.gitmodules` and put each gitlink into the index (after `git add -A`)."""
    if not pinned:
        return
    for p in pinned:
        key = f"submodule.{p.target}"
        git("config", "-f", ".gitmodules", f"{key}.path", p.target)
        git("config", "-f", ".gitmodules", f"{key}.url", p.url)
        git("config", "-f", ".gitmodules", f"{key}.branch", p.branch)
    git("add", ".gitmodules")
    for p in pinned:
        git("update-index", "--add", "--cacheinfo", f"160000,{p.sha},{p.target}")


def write_files(p: Pinned, folder: Path) -> None:
    """The submodule's files at its commit, written into `folder` (for mirrors that take
    the files instead of the submodule)."""
    import tempfile

    from mpc.core.gitrun import GitFailed, git

    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="mpc-archive-") as work:
        archive = Path(work) / "files.tar"
        try:
            git("archive", "--format=tar", "-o", str(archive), p.sha, cwd=p.cache)
        except GitFailed as e:
            raise DeployError("E0803", f"git archive failed in '{p.cache}': {e.message}") from None
        with tarfile.open(archive) as tar:
            extract_data(tar, folder)


def extract_data(tar: tarfile.TarFile, folder: Path) -> None:
    """Extract with tarfile's "data" filter: nothing lands or links outside `folder`, and only
    files, folders and links are made. The filter exists from Python 3.11.4 on; Debian 12's
    python3 is 3.11.2, where the same rules are applied here (TarError when one is broken)."""
    if hasattr(tarfile, "data_filter"):
        tar.extractall(folder, filter="data")
        return
    root = folder.resolve()
    for member in tar.getmembers():
        member.name = member.name.lstrip("/")  # as the filter does: an absolute name lands inside
        dest = (root / member.name).resolve()
        inside = dest.is_relative_to(root)
        if member.issym() or member.islnk():
            link = (dest.parent if member.issym() else root) / member.linkname
            inside = inside and link.resolve().is_relative_to(root)
        if not inside:
            raise tarfile.TarError(f"'{member.name}' would be written or link outside '{folder}'")
        if member.isfile() or member.isdir() or member.issym() or member.islnk():
            tar.extract(member, root, set_attrs=False)
