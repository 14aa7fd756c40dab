"""`mpc run --stages compile,test,deploy`: a model is compiled, tested and deployed in one
run; a rerun with nothing changed does nothing; a changed model whose tests fail goes to
the failure branch with the protocol in its merge request."""

from __future__ import annotations

import json
from pathlib import Path

from tests.deploy.conftest import Model, Server, definition_text, git, heavier
from tests.mpc_command import mpc

PIPELINE = """\
pipeline:
  root: .
  model_definitions: [arm_model.yml]
  remote_base: {base}
  central_meshes: false
"""

TESTED = """\
  test:
    tests:
      - topological_self_consistency
      - total_mass: 3.5
  deployment:
    mr_target_branch: develop
"""


def _run(pipeline: Path) -> tuple[int, dict]:
    done = mpc("run", pipeline, "--stages", "compile,test,deploy", "-j", "1")
    status = json.loads((pipeline.parent / "build/.mpc/status.json").read_text())
    return done.returncode, {stage: (s["state"], s.get("summary", ""))
                             for stage, s in status["models"]["arm-model"]["stages"].items()}


def test_compile_test_deploy_in_one_run(model: Model, server: Server, tmp_path: Path) -> None:
    pipeline = model.folder / "pipeline.yml"
    pipeline.write_text(PIPELINE.format(base=f"{tmp_path}/server/acme/"))
    model.definition.write_text(definition_text(TESTED))
    model.compile()  # writes the arm and commits the definitions

    code, stages = _run(pipeline)
    head = git(server.path, "rev-parse", "master")
    assert code == 0
    assert stages == {"compile": ("ok", "6 files, 1 mesh"), "test": ("ok", "3 passed, 0 failed, 1 skipped"),
                      "deploy": ("ok", f"pushed {head[:10]} to master")}
    options = server.pushes()[-1]["options"]
    assert "merge_request.target=develop" in options
    description = next(o for o in options if o.startswith("merge_request.description="))
    assert "Model tests of `arm-model`: **passed**" in description

    code, stages = _run(pipeline)  # nothing changed: nothing runs, nothing is pushed
    assert code == 0 and {state for state, _ in stages.values()} == {"cached"}
    assert server.log() == ["[mpc] Update arm-model"]

    git(server.path, "branch", "develop", "master")  # the release the merge request goes into
    model.compile(heavier())  # a heavier first link: total_mass fails
    code, stages = _run(pipeline)
    assert code == 1
    assert stages["test"] == ("failed", "2 passed, 1 failed, 1 skipped")
    assert stages["deploy"][0] == "ok"
    assert server.branches()["master"] == head
    assert server.log("tests-failed")[0] == "[mpc] Update arm-model"
    options = server.pushes()[-1]["options"]
    description = next(o for o in options if o.startswith("merge_request.description="))
    assert "Model tests of `arm-model`: **failed**" in description
    assert "total mass 13.5 kg, expected 3.5 kg" in description
    # the changes against the release come first (deploy/review.py)
    assert description.index("## Changes against the release") < description.index("Model tests of")
    assert "<br/>- link `base`: mass 2 → 12 kg (+10)<br/>" in description
