"""A submodule's files are extracted into a mirror with tarfile's "data" rules, also on
Debian 12's Python 3.11.2, whose tarfile has no filters yet."""

from __future__ import annotations

import tarfile
from pathlib import Path

import pytest

from mpc.deploy.submodules import extract_data
from tests.fixtures import tar_archive


# tarfile's own filter where this Python has it (3.11.4 and later), and mpc's rules by hand always
@pytest.fixture(params=[*(["filter"] if hasattr(tarfile, "data_filter") else []), "by hand"])
def python(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    if request.param == "by hand":  # as on Python < 3.11.4
        monkeypatch.delattr(tarfile, "data_filter", raising=False)
    return str(request.param)


def test_files_and_links_inside_are_extracted(tmp_path: Path, python: str) -> None:
    extract_data(tar_archive(("lua/knee.lua", b"-- lua\n"), ("lua/link.lua", "knee.lua"), ("/abs", b"a")),
                  tmp_path / "out")
    assert (tmp_path / "out/lua/knee.lua").read_bytes() == b"-- lua\n"
    assert (tmp_path / "out/lua/link.lua").readlink() == Path("knee.lua")
    assert (tmp_path / "out/abs").read_bytes() == b"a"  # an absolute name lands inside


@pytest.mark.parametrize("member", [("../evil", b"x"), ("lua/secret", "/etc/passwd"),
                                    ("lua/up", "../../x")])
def test_nothing_is_written_or_linked_outside(tmp_path: Path, python: str,
                                              member: tuple[str, bytes | str]) -> None:
    with pytest.raises(tarfile.TarError):
        extract_data(tar_archive(member), tmp_path / "out")
    assert sorted(p.name for p in tmp_path.rglob("*")) in ([], ["out"])
