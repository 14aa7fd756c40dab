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


def test_two_builds_of_the_bundled_examples_are_byte_identical(tmp_path: Path) -> None:
    """Every output file, the PDFs of the kinematic trees included (cairo stamps the time of
    rendering into them), is the same in two builds a second apart, the second from the cache."""
    import shutil
    import time

    from tests.pipeline.helpers import mpc

    for n, build in enumerate(("first", "second")):
        if n:
            time.sleep(1.1)  # a PDF stamped with the time would now differ
        for example in EXAMPLES:
            out = tmp_path / build / example.stem
            assert compile_file(example, out, Diags()).out is not None
        fleet = tmp_path / build / "fleet"
        shutil.copytree(EXAMPLES[0].parent / "fleet", fleet)
        # Cold, then warm: what a build with the cache writes is what one without it wrote.
        run = mpc("run", fleet / "pipeline.yml", cache=tmp_path / "cache")
        assert run.returncode == 1, run.stderr  # broken.yml fails on purpose
    first, second = _files(tmp_path / "first"), _files(tmp_path / "second")
    assert sorted(first) == sorted(second)
    assert [f for f in first if f.endswith(".pdf")]
    assert [f for f in first if first[f] != second[f]] == []
