"""The bundled examples check clean and compile: what a new user runs first never rots."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.compiler.driver import Options, check_file
from tests.conftest import Diags, compile_file

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.yml"))


def test_there_are_examples() -> None:
    assert [p.name for p in EXAMPLES] == ["a1_from_parts.yml", "talos.yml"]


@pytest.mark.parametrize("example", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_checks_clean_and_compiles(example: Path, tmp_path: Path, diags: Diags) -> None:
    check_file(example, diags, Options())
    assert not diags.diagnostics
    assert compile_file(example, tmp_path / "out", diags).out is not None
