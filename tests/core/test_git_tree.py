"""A commit's files unpacked (core/git_tree.py) as tarfile's `data` filter would, also on Debian
12's Python 3.11.2, which lacks that filter: what stays inside the folder is written, anything
else is refused."""

from __future__ import annotations

import io
import tarfile
from pathlib import Path

import git
import pytest

from mpc.core.git_tree import COMPLETE, _unpack, write_tree


def _tar(*members: tuple[str, bytes | None, str]) -> tarfile.TarFile:
    """(name, data, link) each: a file with data, a link to `link` (data None)."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w") as tar:
        for name, data, link in members:
            info = tarfile.TarInfo(name)
            if data is None:
                info.type, info.linkname = tarfile.SYMTYPE, link
                tar.addfile(info)
            else:
                info.size = len(data)
                tar.addfile(info, io.BytesIO(data))
    buffer.seek(0)
    return tarfile.open(fileobj=buffer)


def test_a_commit_is_written_whole(tmp_path: Path) -> None:
    repo = git.Repo.init(tmp_path / "repo")
    (tmp_path / "repo/urdf").mkdir()
    (tmp_path / "repo/urdf/arm.urdf").write_text("<robot/>\n")
    (tmp_path / "repo/run.sh").write_text("#!/bin/sh\n")
    (tmp_path / "repo/run.sh").chmod(0o755)
    (tmp_path / "repo/same.urdf").symlink_to("urdf/arm.urdf")
    repo.index.add(["urdf/arm.urdf", "run.sh", "same.urdf"])
    commit = repo.index.commit("one").hexsha
    write_tree(tmp_path / "repo", commit, tmp_path / "tree")
    assert (tmp_path / "tree/urdf/arm.urdf").read_text() == "<robot/>\n"
    assert (tmp_path / "tree/same.urdf").read_text() == "<robot/>\n"  # a link inside the tree
    assert (tmp_path / "tree/run.sh").stat().st_mode & 0o777 == 0o755
    assert (tmp_path / "tree" / COMPLETE).read_text() == commit + "\n"


@pytest.mark.parametrize(("members", "why"), [
    ((("../escape", b"x", ""),), "'../escape' points outside the tree"),
    ((("/abs", b"x", ""),), "'/abs' points outside the tree"),
    ((("a/../../b", b"x", ""),), "'a/../../b' points outside the tree"),
    ((("out", None, "../../etc/passwd"),), "the link 'out' points outside the tree"),
    ((("a/out", None, "../.."),), "the link 'a/out' points outside the tree"),
    ((("out", None, "/etc/passwd"),), "the link 'out' points outside the tree"),
])
def test_what_points_outside_is_refused(tmp_path: Path, members: tuple, why: str) -> None:
    with _tar(*members) as tar, pytest.raises(tarfile.TarError) as refused:
        _unpack(tar, tmp_path / "files")
    assert str(refused.value) == why
    assert not (tmp_path / "escape").exists() and not (tmp_path / "b").exists()
