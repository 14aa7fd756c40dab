"""What a build records as its inputs (core/reads.py): the files it opened, less code and the
installation's metadata."""

from __future__ import annotations

from pathlib import Path

from mpc.core.reads import ReadRecorder, recording


def test_distribution_metadata_is_no_input_of_a_build(tmp_path: Path) -> None:
    """pydantic reads every installed distribution's entry points for plugins as it builds its
    first validator (in a program that is not `mpc`'s, which gives it none): a build made in a
    checkout set up by scripts/setup.sh depended on the checkout's `.egg-info`, which each
    reinstall rewrites."""
    files = [tmp_path / "model_pipeline_compiler.egg-info/entry_points.txt",
             tmp_path / "site/pydantic-2.0.dist-info/entry_points.txt", tmp_path / "robot.urdf"]
    for file in files:
        file.parent.mkdir(parents=True, exist_ok=True)
        file.write_text("x")
    with recording(ReadRecorder()) as recorder:
        for file in files:
            file.read_text()
    assert recorder.inputs() == [tmp_path / "robot.urdf"]
