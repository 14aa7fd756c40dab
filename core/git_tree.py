"""A commit's files → a folder: what `mpc diff PATH@REV` reads and what `mpc deploy` compares
the build with (the release on the merge request's target branch).

`git archive` of the commit, unpacked as tarfile's `data` filter would (`_unpack`; that filter
is missing from Debian 12's Python 3.11.2): folders, regular files and links that stay inside
the folder; an absolute or `..` path, a link out of the folder or any other kind of member is
refused (TarError). The files git tracks, without LFS contents or submodules. The folder is
written beside, then renamed into place, so it is whole or absent.
"""

from __future__ import annotations

import os
import shutil
import tarfile
import tempfile
from pathlib import Path

from mpc.core.gitrun import git

COMPLETE = ".mpc-complete"  # written last into a whole tree


def write_tree(repository: Path, commit: str, tree: Path) -> None:
    """The files of `commit` of the repository at `repository` into `tree` (made here; another
    run's whole tree there is taken as it is). Raises GitFailed, OSError or TarError."""
    if (tree / COMPLETE).is_file():
        return
    tree.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{commit[:12]}-", dir=tree.parent))
    try:
        archive = staging / "tree.tar"
        git("archive", "--format=tar", "-o", str(archive), commit, cwd=repository)
        files = staging / "files"
        with tarfile.open(archive) as tar:
            _unpack(tar, files)
        (files / COMPLETE).write_text(commit + "\n")
        try:
            os.rename(files, tree)
        except OSError:
            if not (tree / COMPLETE).is_file():  # not another run's whole tree
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _inside(name: str) -> str:
    """`name` as a path inside the folder, or TarError."""
    parts = name.split("/")
    if name.startswith("/") or ".." in parts:
        raise tarfile.TarError(f"'{name}' points outside the tree")
    return os.path.join(*[p for p in parts if p not in ("", ".")]) if name.strip("/.") else ""


def _unpack(tar: tarfile.TarFile, folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for member in tar:
        name = _inside(member.name)
        if not name:
            continue
        target = folder / name
        if member.isdir():
            target.mkdir(parents=True, exist_ok=True)
        elif member.isfile():
            target.parent.mkdir(parents=True, exist_ok=True)
            source = tar.extractfile(member)
            assert source is not None  # a regular file's data
            with source, open(target, "wb") as out:
                shutil.copyfileobj(source, out)
            os.chmod(target, 0o755 if member.mode & 0o111 else 0o644)
        elif member.issym():
            points_to = os.path.normpath(os.path.join(os.path.dirname(name), member.linkname))
            if os.path.isabs(member.linkname) or points_to == ".." or points_to.startswith("../"):
                raise tarfile.TarError(f"the link '{member.name}' points outside the tree")
            target.parent.mkdir(parents=True, exist_ok=True)
            os.symlink(member.linkname, target)
        else:
            raise tarfile.TarError(f"'{member.name}' is neither a file, a folder nor a link")
