"""A pipeline's `root` (issue 35.6): `mpc run` writes `<root>/build`, so a root outside the
pipeline file's folder and its parent needs `--allow-root-outside`; without it, E0621 at
`root` and nothing is written."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import ERD, write
from tests.pipeline.helpers import mpc

PENDULUM = ERD / "double_pendulum_description/urdf/double_pendulum_simple.urdf"
MODEL = (f'model:\n  robotname: p\n  modelname: p\n  input_models: {{b: {{basefile: "{PENDULUM}"}}}}\n'
         "  assemble: {model: b}\n  export_config:\n    - type: urdf\n      mesh_format: input_type\n")


def _pipeline(folder: Path, root: str, definition: str = "p.yml") -> Path:
    return write(folder / "pipeline.yml", f"pipeline:\n  root: {root}\n  model_definitions: [{definition}]\n")


def test_root_slash_is_refused_at_its_line_and_writes_no_build(tmp_path: Path) -> None:
    project = tmp_path / "project"
    write(project / "p.yml", MODEL)
    pipeline = _pipeline(project, "/")
    assert not Path("/build").exists()
    done = mpc("run", pipeline, cwd=project, cache=tmp_path / "cache")
    assert done.returncode == 1, done.stderr
    assert (f"pipeline.yml:2:9: error[E0621]: the workspace root '/' is outside the pipeline file's "
            f"folder '{project}' and its parent; `mpc run` would write '/build'") in done.stderr
    assert "hint: give --allow-root-outside when this root is meant" in done.stderr
    assert not Path("/build").exists()
    assert sorted(p.name for p in project.iterdir()) == ["p.yml", "pipeline.yml"]


@pytest.mark.parametrize("root", ["../..", "../other", "$MPC_TEST_ROOT"])
def test_a_root_outside_needs_the_flag(tmp_path: Path, root: str) -> None:
    project = tmp_path / "a" / "ci"
    write(project / "p.yml", MODEL)
    (tmp_path / "a" / "other").mkdir()
    pipeline = _pipeline(project, root)
    environ = {"MPC_TEST_ROOT": str(tmp_path)}
    refused = mpc("run", pipeline, cwd=project, cache=tmp_path / "cache", environ=environ)
    assert refused.returncode == 1 and "error[E0621]" in refused.stderr, refused.stderr
    assert not list(tmp_path.rglob("build"))
    done = mpc("run", pipeline, "--allow-root-outside", cwd=project, cache=tmp_path / "cache",
               environ=environ)
    if root == "../other":  # the definition is outside this root: the model fails (E0641)
        assert "E0641" in done.stderr and "E0621" not in done.stderr
    else:
        assert done.returncode == 0, done.stderr
        assert (tmp_path / "build/p/urdf/p.urdf").is_file()  # both name tmp_path


@pytest.mark.parametrize(("root", "build"), [(".", "ci/build"), ("..", "build"), ("sub", "ci/sub/build")])
def test_the_pipeline_folder_its_parent_and_folders_inside_need_no_flag(
        tmp_path: Path, root: str, build: str) -> None:
    project = tmp_path / "ci"
    (project / "sub").mkdir(parents=True)
    write(project / "sub" / "p.yml", MODEL)
    pipeline = _pipeline(project, root, "sub/p.yml")
    done = mpc("run", pipeline, cwd=project, cache=tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / build / "p/urdf/p.urdf").is_file()


def test_check_warns_and_ci_passes_the_flag_to_its_jobs(tmp_path: Path) -> None:
    project = tmp_path / "a" / "ci"
    write(project / "p.yml", MODEL)
    pipeline = _pipeline(project, "../..")
    checked = mpc("check", pipeline, cwd=tmp_path)
    assert checked.returncode == 0, checked.stderr
    assert "warning[W0624]: the workspace root" in checked.stderr
    refused = mpc("ci", "gitlab", pipeline, "--image", "x", cwd=tmp_path)
    assert refused.returncode == 1 and "error[E0621]" in refused.stderr
    made = mpc("ci", "gitlab", pipeline, "--image", "x", "--allow-root-outside", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    jobs = [line for line in made.stdout.splitlines() if "mpc ci job" in line or "mpc ci summary" in line]
    assert jobs and all(line.endswith("--allow-root-outside") for line in jobs), jobs
