"""A commit's files → a folder: what `mpc diff PATH@REV` reads and what `mpc deploy` compares
the build with (the release on the merge request's target branch).

`git archive` of the commit, unpacked with tarfile's `data` filter (no link out of the
folder, no device, no absolute path): the files git tracks, without LFS contents or
submodules. The folder is written beside, then renamed into place, so it is whole or absent.
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
            tar.extractall(files, filter="data")
        (files / COMPLETE).write_text(commit + "\n")
        try:
            os.rename(files, tree)
        except OSError:
            if not (tree / COMPLETE).is_file():  # not another run's whole tree
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
