"""`mpc deploy` from the command line with a pipeline file: defaults merged under the
model's deployment, the workdir under the pipeline's root, dry runs, exit codes."""

from __future__ import annotations

from pathlib import Path

from tests.deploy.conftest import SMURF_FILES, Model, Server, definition_text, git
from tests.mpc_command import mpc

PIPELINE = """\
pipeline:
  model_definitions: [arm_model.yml]
  remote_base: {base}
  central_meshes: false
  mr_mention: "@carol"
  default_deployment:
    mr_title: Default title
    mr_target_branch: release
    keep_files: ["notes/*"]
"""


def _pipeline(model: Model, tmp_path: Path) -> Path:
    path = model.folder / "pipeline.yml"
    path.write_text(PIPELINE.format(base=f"{tmp_path}/server/acme/"))
    model.definition.write_text(definition_text("  deployment:\n    mr_target_branch: develop\n"))
    return path


def test_dry_run_then_deploy_with_a_pipeline(model: Model, server: Server, tmp_path: Path) -> None:
    pipeline = _pipeline(model, tmp_path)
    server.commit_files({"notes/todo.md": "- more links\n", "old.txt": "x\n"}, "by hand")
    model.compile()
    dry = mpc("deploy", model.definition, "--built", model.built, "--pipeline", pipeline, "--dry-run")
    assert dry.returncode == 0, dry.stderr
    url = f"{tmp_path}/server/acme/arm-model"
    lines = dry.stdout.splitlines()
    assert lines[0] == f"dry run: would push to branch 'master' of '{url}':"
    assert [line.split("|")[0].strip() for line in lines[1:-1]] == [
        "README.md", "meshes/stl/tetra.stl", "old.txt", "smurf/arm.smurf", *SMURF_FILES, "urdf/arm.urdf"]
    assert lines[-1].strip() == "9 files changed, 92 insertions(+), 1 deletion(-)"
    assert server.log() == ["by hand"] and (tmp_path / ".mpc-deploy" / "arm-model" / ".git").is_dir()

    run = mpc("deploy", model.definition, "--built", model.built, "--pipeline", pipeline)
    assert run.returncode == 0, run.stderr
    head = git(server.path, "rev-parse", "master")
    assert run.stdout == (f"deployed 'arm-model' to branch 'master' of '{url}': commit {head[:12]}\n"
                          "  merge request into 'develop'\n")
    assert sorted(server.files()) == ["README.md", "meshes/stl/tetra.stl", "notes/todo.md", "smurf/arm.smurf",
                                       *SMURF_FILES, "urdf/arm.urdf"]
    options = server.pushes()[-1]["options"]
    assert options[1:3] == ["merge_request.target=develop", "merge_request.title=Default title"]
    assert options[-1] == "merge_request.assign=carol"
    assert "Maintainers: @carol" in server.show("master", "README.md")

    again = mpc("deploy", model.definition, "--built", model.built, "--pipeline", pipeline)
    assert again.stdout == f"'arm-model': nothing changed on branch 'master' of '{url}'\n"


def test_failed_deploy_exits_1(model: Model, tmp_path: Path) -> None:
    model.compile()
    run = mpc("deploy", model.definition, "--built", model.built, "--remote", tmp_path / "missing.git",
              "--workdir", tmp_path / "work")
    assert run.returncode == 1
    assert "error[E0803]: git clone failed in" in run.stderr
    assert run.stderr.endswith(f"error: could not deploy '{model.definition}'\n")


def test_cli_refuses_pipeline_and_remote_together(model: Model) -> None:
    run = mpc("deploy", model.definition, "--built", "b", "--pipeline", "p.yml", "--remote", "r")
    assert run.returncode == 2
    assert "argument --remote: not allowed with argument --pipeline" in run.stderr


def test_deploy_takes_package_as_every_command_that_reads_definitions(
        model: Model, server: Server, tmp_path: Path) -> None:
    """Its hint names `--package`: `mpc deploy` takes it (and `--werror`), as compile does."""
    model.compile()
    model.definition.write_text(definition_text().replace("basefile: arm.urdf",
                                                          "basefile: package://arm_pkg/arm.urdf"))
    git(model.folder, "commit", "-qam", "the arm from its package")
    deploy = ("deploy", model.definition, "--built", model.built, "--remote", server.url, "--dry-run",
              "--workdir", tmp_path / "work")
    missing = mpc(*deploy)
    assert missing.returncode == 1
    assert "hint: map the package with --package NAME=DIR or ROS_PACKAGE_PATH" in missing.stderr
    found = mpc(*deploy, "--package", f"arm_pkg={model.folder}")
    assert found.returncode == 0, found.stderr
    assert found.stdout.startswith(f"dry run: would push to branch 'master' of '{server.url}':")
