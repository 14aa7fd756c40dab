"""What a build records as its inputs (core/reads.py): the files it opened, less code and the
installation's metadata."""

from __future__ import annotations

from pathlib import Path

from mpc.core.reads import ReadRecorder, recording


def test_distribution_metadata_is_no_input_of_a_build(tmp_path: Path) -> None:
    """Libraries read installed distributions' entry points for plugins (pydantic did, when
    the schema was declared in it): a build made in a checkout set up by scripts/setup.sh
    depended on the checkout's `.egg-info`, which each reinstall rewrites."""
    files = [tmp_path / "model_pipeline_compiler.egg-info/entry_points.txt",
             tmp_path / "site/somelib-2.0.dist-info/entry_points.txt", tmp_path / "robot.urdf"]
    for file in files:
        file.parent.mkdir(parents=True, exist_ok=True)
        file.write_text("x")
    with recording(ReadRecorder()) as recorder:
        for file in files:
            file.read_text()
    assert recorder.inputs() == [tmp_path / "robot.urdf"]
