"""A commit's files unpacked (core/git_tree.py) as tarfile's `data` filter would, also on Debian
12's Python 3.11.2, which lacks that filter: what stays inside the folder is written, anything
else is refused."""

from __future__ import annotations

import tarfile
from pathlib import Path

import git
import pytest

from mpc.core.git_tree import COMPLETE, _unpack, write_tree
from tests.fixtures import tar_archive


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
    ((("../escape", b"x"),), "'../escape' points outside the tree"),
    ((("/abs", b"x"),), "'/abs' points outside the tree"),
    ((("a/../../b", b"x"),), "'a/../../b' points outside the tree"),
    ((("out", "../../etc/passwd"),), "the link 'out' points outside the tree"),
    ((("a/out", "../.."),), "the link 'a/out' points outside the tree"),
    ((("out", "/etc/passwd"),), "the link 'out' points outside the tree"),
])
def test_what_points_outside_is_refused(tmp_path: Path, members: tuple, why: str) -> None:
    with tar_archive(*members) as tar, pytest.raises(tarfile.TarError) as refused:
        _unpack(tar, tmp_path / "files")
    assert str(refused.value) == why
    assert not (tmp_path / "escape").exists() and not (tmp_path / "b").exists()
