"""The GitLab child pipeline `mpc ci gitlab` writes for examples/fleet, run for real: with
gitlab-ci-local (npm; scripts/setup.sh installs it) in shell-executor mode with
`--shell-isolation`, in a team's repository made in a temporary folder. Its jobs install
the mpc of this checkout the way a team pins it: a wheel in the repository, named in its
requirements.txt with the other packages at the lock's versions.

Every job passes but the broken model's and its dependant's, which fail as `mpc run`
reports them; the outputs equal `mpc run`'s byte for byte; a second pipeline (a new
checkout: no artifacts, only the caches) of the two models that convert meshes converts none.
"""

from __future__ import annotations

import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.pipeline.helpers import FLEET, ROOT, mpc

UV = Path(sys.executable).parent / "uv"  # the dev extra's uv
# Four of the fleet's twelve models, each kind of job once: a model with DAE meshes, one that
# derives from it (its job needs the parent's artifacts), and the broken model with its
# dependant. Each job installs mpc in a fresh environment: the whole fleet would take three
# times as long and prove nothing more.
MODELS = ["arm", "arm_prefixed"]
DEFINITIONS = [*MODELS, "broken", "broken_child"]


def fleet(to: Path) -> Path:
    """examples/fleet copied to `to`, its pipeline.yml listing DEFINITIONS only."""
    shutil.copytree(FLEET, to)
    pipeline = to / "pipeline.yml"
    head, _, tail = pipeline.read_text().partition("  model_definitions:\n")
    listed = "".join(f"    - {name}.yml\n" for name in DEFINITIONS)
    exports = tail[tail.index("  default_export_config"):]
    pipeline.write_text(f"{head}  model_definitions:\n{listed}{exports}")
    return pipeline


def _git(top: Path, *args: str) -> None:
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@example.com", *args], cwd=top,
                   check=True, capture_output=True)


def _tracked_files(to: Path) -> Path:
    """The checkout's tracked files copied to `to`: setuptools leaves build/ in the tree it builds."""
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for name in filter(None, listed.decode().split("\0")):
        if (ROOT / name).is_file():  # a file deleted but not yet staged is listed too
            (to / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, to / name)
    return to


@pytest.fixture(scope="module")
def team(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A definitions repository that pins this mpc (a wheel built from this checkout)."""
    top = tmp_path_factory.mktemp("team")
    fleet(top / "fleet")
    source = _tracked_files(top.parent / f"{top.name}-src")
    # uv fetches setuptools trusting the system's certificates, as scripts/setup.sh has it do
    built = subprocess.run([str(UV), "build", "--system-certs", "--wheel", "--quiet", "--out-dir",
                            str(top / "wheels"), str(source)], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    (top / "wheels" / ".gitignore").unlink(missing_ok=True)  # uv build ignores its output folder
    [wheel] = (top / "wheels").glob("*.whl")

    def pins(*extra: str) -> list[str]:
        done = subprocess.run([str(UV), "export", "--frozen", "--no-hashes", "--no-emit-project",
                               "--no-header", "--no-annotate", *extra, "--project", str(ROOT)],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout.splitlines(keepends=True)

    # mpc's own packages, and example-robot-data: the fleet's package:// models
    robots = [line for line in pins("--extra", "dev") if line.startswith("example-robot-data==")]
    assert len(robots) == 1
    (top / "requirements.txt").write_text("".join(pins() + robots) + f"./wheels/{wheel.name}\n")
    (top / ".gitignore").write_text("build/\n.cache/\n.mpc-venv/\n.gitlab-ci-local/\nchild.yml\n")
    _git(top, "init", "-q")
    _git(top, "add", "-A")
    _git(top, "commit", "-qm", "the fleet")
    done = mpc("ci", "gitlab", "fleet/pipeline.yml", "-o", "child.yml", cwd=top)
    assert (done.returncode, done.stdout) == (0, "wrote child.yml: 4 models, 5 jobs\n"), done.stderr
    yield top
    shutil.rmtree(top / ".gitlab-ci-local", ignore_errors=True)  # its jobs' venvs: 1.8 GB


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """What `mpc run` builds and reports for the fleet on one machine."""
    top = tmp_path_factory.mktemp("reference")
    fleet(top / "fleet")
    done = mpc("run", "fleet/pipeline.yml", cwd=top, cache=top / "cache")
    assert done.returncode == 1, done.stderr
    return {"build": top / "fleet" / "build",
            "status": json.loads((top / "fleet/build/.mpc/status.json").read_text())}


def _run_pipeline(top: Path, *jobs: str) -> tuple[subprocess.CompletedProcess[str], dict[str, str]]:
    """One pipeline run of child.yml (of `jobs` only, when given), as a new pipeline: no
    artifacts, the caches of earlier runs."""
    state = top / ".gitlab-ci-local"
    for old in (state / "artifacts", state / "builds", top / "fleet/build"):
        shutil.rmtree(old, ignore_errors=True)
    tools = top.parent / f"{top.name}-tools"
    tools.mkdir(exist_ok=True)
    if not (tools / "uv").exists():
        (tools / "uv").symlink_to(UV)  # uv alone: the jobs must install mpc themselves
    path = [p for p in os.environ["PATH"].split(os.pathsep) if p and not (Path(p) / "mpc").exists()]
    # a runner's environment: none of this machine's Python, mpc or uv settings (and Python
    # writes bytecode, as it does by default, so a job's second mpc process starts sooner)
    drop = ("VIRTUAL_ENV", "MPC_", "UV_", "GITLAB", "PYTHONDONTWRITEBYTECODE")
    env = {k: v for k, v in os.environ.items() if not k.startswith(drop)}
    env["PATH"] = os.pathsep.join([str(tools), *path])
    uv_cache = subprocess.run([str(UV), "cache", "dir"], capture_output=True, text=True,
                              check=True).stdout.strip()
    variables = {"UV_CACHE_DIR": uv_cache,  # this machine's: the packages are there already
                 "UV_PYTHON_DOWNLOADS": "never", "UV_PYTHON": sys._base_executable}
    argv = ["gitlab-ci-local", "--file", "child.yml", "--shell-isolation", "--concurrency", "2", "--no-color",
            "--home", str(tools), *(a for k, v in variables.items() for a in ("--variable", f"{k}={v}")),
            *jobs]
    done = subprocess.run(argv, cwd=top, env=env, capture_output=True, text=True, timeout=900)
    verdicts = re.findall(r"^\s*(PASS|FAIL)\s+(\S+)", done.stdout, re.M)
    results = {job: verdict for verdict, job in verdicts}
    return done, results


def _same_tree(a: Path, b: Path) -> list[str]:
    """Files that differ between two folders, or exist in one only."""
    left = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    right = sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    if left != right:
        return [str(p) for p in sorted(set(left) ^ set(right))]
    return [str(p) for p in left if not filecmp.cmp(a / p, b / p, shallow=False)]


def _states(status: dict[str, Any]) -> dict[str, tuple[str, str, list[tuple[str, str]]]]:
    """Per model: its compile state, the reason or summary, and its diagnostics (code, message)."""
    out = {}
    for name, model in status["models"].items():
        stage = model["stages"]["compile"]
        out[name] = (stage["state"], stage.get("reason") or stage.get("summary", ""),
                     [(d["code"], d["message"]) for d in stage.get("diagnostics", [])])
    return out


@pytest.mark.long
def test_the_fleet_pipeline_runs_in_gitlab_ci_local(team: Path, reference: dict[str, Any]) -> None:
    expected = {f"build:{m}": "PASS" for m in MODELS} | {"summary": "PASS", "build:broken": "FAIL",
                                                        "build:broken_child": "FAIL"}
    first, results = _run_pipeline(team)
    assert results == expected, first.stdout[-4000:] + first.stderr
    status = json.loads((team / "fleet/build/.mpc/status.json").read_text())
    assert _states(status) == _states(reference["status"])
    assert _states(status)["broken_child"] == ("skipped", "derived_base 'broken' failed", [])
    assert status["counts"] == {"ok": 2, "failed": 1, "skipped": 1}
    for model in MODELS:
        assert _same_tree(team / "fleet/build" / model, reference["build"] / model) == [], model
    made = status["cache"]["made"]
    assert made > 0  # the arm's DAE meshes converted to STL
    assert "| broken_child | skipped |  | derived_base 'broken' failed |" in (
        team / "fleet/build/.mpc/summary.md").read_text()

    jobs = [f"build:{m}" for m in MODELS]
    second, results = _run_pipeline(team, *jobs)
    assert results == {job: "PASS" for job in jobs}, second.stdout[-4000:] + second.stderr
    counts = re.findall(r"^\S+\s+> cache: (\d+) entries made, (\d+) reused\s*$", second.stdout, re.M)
    assert len(counts) == len(jobs), second.stdout[-4000:]
    # every mesh came from the pushed cache: each entry the first run made (the DAE files are
    # read into arrays, not kept in a normalized form: backends/plain_meshes.py)
    assert [sum(int(c[i]) for c in counts) for i in (0, 1)] == [0, made]
    for model in MODELS:
        assert _same_tree(team / "fleet/build" / model, reference["build"] / model) == [], model
