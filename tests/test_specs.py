"""specs/ stays true: its runnable examples compile, and every diagnostic code is listed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.conftest import Diags, compile_file

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"


def _examples() -> list[tuple[str, str]]:
    found = []
    for page in sorted(SPECS.glob("*.md")):
        for block in re.findall(r"```yaml\n(.*?)```", page.read_text(), re.DOTALL):
            m = re.match(r"# example: (\S+)", block)
            if m:
                found.append((f"{page.stem}:{m.group(1)}", block))
    return found


EXAMPLES = _examples()


def test_there_are_examples() -> None:
    assert len(EXAMPLES) >= 1


@pytest.mark.parametrize(("name", "text"), EXAMPLES, ids=[n for n, _ in EXAMPLES])
def test_example_compiles_cleanly(name: str, text: str, tmp_path: Path, diags: Diags) -> None:
    spec = tmp_path / "example.yml"
    spec.write_text(text)
    assert compile_file(spec, tmp_path / "out", diags).out is not None


def test_every_code_is_documented() -> None:
    used = set()
    for folder in ("compiler", "backends", "ir"):
        for path in (ROOT / folder).rglob("*.py"):
            used |= set(re.findall(r'"([EW]\d{4})"', path.read_text()))
    documented = set(re.findall(r"^\| ([EW]\d{4}) \|", (SPECS / "diagnostics.md").read_text(), re.M))
    assert used == documented
