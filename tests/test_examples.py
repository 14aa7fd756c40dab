"""The bundled examples check clean and compile: what a new user runs first never rots."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.cli.check import check_file
from mpc.compiler.options import Options
from tests.conftest import Diags, compile_file

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.yml"))


def test_there_are_examples() -> None:
    assert [p.name for p in EXAMPLES] == ["a1_from_parts.yml", "talos.yml"]


@pytest.mark.parametrize("example", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_checks_clean_and_compiles(example: Path, tmp_path: Path, diags: Diags) -> None:
    check_file(example, diags, Options())
    assert not diags.diagnostics
    assert compile_file(example, tmp_path / "out", diags).out is not None


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and ".mpc" not in p.relative_to(folder).parts}


def test_two_builds_of_the_bundled_examples_are_byte_identical(tmp_path: Path,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """Every output file, the PDFs of the kinematic trees (cairo stamps the time of rendering
    into them) and the COLLADA meshes mpc writes (pycollada stamps the time and random ids)
    included, is the same in two builds a second apart on two caches (two machines), and
    in a third on the first's cache (its kept builds and meshes)."""
    import shutil
    import time

    from tests.pipeline.helpers import mpc

    for n, (build, cache) in enumerate((("first", "a"), ("second", "b"), ("third", "a"))):
        if n:
            time.sleep(1.1)  # a file stamped with the time would now differ
        monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / cache))
        for example in EXAMPLES:
            out = tmp_path / build / example.stem
            assert compile_file(example, out, Diags()).out is not None
        fleet = tmp_path / build / "fleet"
        shutil.copytree(EXAMPLES[0].parent / "fleet", fleet)
        run = mpc("run", fleet / "pipeline.yml", cache=tmp_path / cache)
        assert run.returncode == 1, run.stderr  # broken.yml fails on purpose
    first = _files(tmp_path / "first")
    assert [f for f in first if f.endswith(".pdf")] and [f for f in first if f.endswith(".dae")]
    for other in ("second", "third"):
        files = _files(tmp_path / other)
        assert sorted(files) == sorted(first)
        assert [f for f in first if first[f] != files[f]] == [], other
