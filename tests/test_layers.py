"""The floors of specs/layers.md hold: `lint-imports` (the contracts in pyproject.toml) finds no
import of a higher floor and no import cycle, lazy imports included."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_no_floor_imports_a_higher_one_and_no_module_imports_in_a_circle() -> None:
    lint = Path(sys.executable).parent / "lint-imports"
    done = subprocess.run([str(lint), "--no-cache"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 kept, 0 broken" in done.stdout
