"""`mpc run --no-post-processing` (issue 35.7): the definitions' commands do not run, and a
later run with them is no cached copy of that build."""

from __future__ import annotations

from pathlib import Path

from tests.conftest import write
from tests.pipeline.helpers import mpc
from tests.pipeline.test_root import MODEL


def test_run_without_post_processing_runs_no_command_and_a_later_run_does(tmp_path: Path) -> None:
    canary = tmp_path / "canary"
    write(tmp_path / "p.yml", MODEL + f"  post_processing:\n    - cmd: [touch, '{canary}']\n")
    pipeline = write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [p.yml]\n")
    done = mpc("run", pipeline, "--no-post-processing", cwd=tmp_path, cache=tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "build/p/urdf/p.urdf").is_file() and not canary.exists()
    done = mpc("run", pipeline, cwd=tmp_path, cache=tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    assert canary.exists()
