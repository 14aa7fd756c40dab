"""A compare model cloned from a real git repository (a bare repository on disk), at a branch
or a commit; `ignore_failing_tests_for` waives failures only at the commit it names."""

from __future__ import annotations

import shutil
from pathlib import Path

import git
import pytest

from mpc.core.diagnostics import Sink
from tests.checks.helpers import (
    compile_ok,
    definition,
    edited_urdf,
    failing,
    link_el,
    result,
    run,
    statuses,
    write,
)
from tests.conftest import ERD

SOLO = ERD / "solo_description/robots/solo12.urdf"
TESTS = "      - compare_link_masses\n      - hyrodynChecks: [compare_masses, compare_com]\n"


def heavier_solo(tmp_path: Path) -> Path:
    def edit(root):
        mass = link_el(root, "FL_LOWER_LEG").find("inertial/mass")
        mass.set("value", repr(float(mass.get("value")) + 0.05))
    return edited_urdf(SOLO, tmp_path / "in/solo12.urdf", edit)


@pytest.fixture
def remote(tmp_path: Path) -> tuple[Path, str, str]:
    """A bare repository whose master has two commits: the released solo12 output, then one
    with a link 50 g heavier. Returns the repository and both commits."""
    bare = tmp_path / "models.git"
    git.Repo.init(bare, bare=True, initial_branch="master")
    work = git.Repo.clone_from(str(bare), tmp_path / "clone")
    commits = []
    for i, source in enumerate((SOLO, heavier_solo(tmp_path))):
        write(tmp_path / f"rel{i}.yml", definition(source, "solo", "      - compare_amount_joints\n"))
        compile_ok(tmp_path / f"rel{i}.yml", tmp_path / f"rel{i}")
        target = Path(work.working_tree_dir) / "urdf"
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(tmp_path / f"rel{i}" / "urdf", target)
        work.index.add(["urdf/solo.urdf"])
        commits.append(work.index.commit(f"release {i}").hexsha)
    work.remote().push("master")
    return bare, commits[0], commits[1]


def compare(repo: Path, **keys: str) -> str:
    lines = [f"      git: {repo}\n", "      model_in_repo: urdf/solo.urdf\n"]
    return "".join(lines + [f'      {k}: "{v}"\n' for k, v in keys.items()])


def test_compare_at_a_commit_finds_the_difference_and_a_waiver_for_another_commit_does_not_apply(
        tmp_path: Path, remote: tuple[Path, str, str]) -> None:
    repo, first, second = remote
    keys = compare(repo, commit=first[:10], ignore_failing_tests_for=second[:8])
    write(tmp_path / "m.yml", definition(heavier_solo(tmp_path), "solo", TESTS, keys))
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")
    assert protocol.compare == f"`models.git` at commit `{first[:12]}`"  # not the runner's path
    assert f"\n\nCompared with `models.git` at commit `{first[:12]}`.\n\n" in protocol.markdown()
    assert protocol.waiver == ""
    assert failing(protocol) == {"compare_link_masses", "compare_masses", "compare_com"}  # 50 g on 2.5 kg
    assert statuses(protocol)["compare_link_masses"] == "failed"
    assert result(protocol, "compare_link_masses").figure == pytest.approx(0.05)
    assert protocol.failed


def test_the_waiver_applies_at_the_commit_it_names(tmp_path: Path, remote: tuple[Path, str, str]) -> None:
    repo, _, second = remote  # master is at the second (heavier) release; the new model is the original
    write(tmp_path / "m.yml", definition(SOLO, "solo", TESTS,
                                         compare(repo, branch="master", ignore_failing_tests_for=second[:8])))
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")
    s = statuses(protocol)
    assert (s["compare_link_masses"], s["compare_masses"], s["compare_com"]) == ("waived",) * 3
    assert s["topological_self_consistency"] == "passed"
    assert result(protocol, "compare_masses").reason.endswith(
        f"(waived: the compare model is at commit {second[:12]}, which ignore_failing_tests_for names)")
    assert not protocol.failed
    assert "⚠️ waived" in protocol.markdown()


def test_the_same_model_at_the_first_commit_passes(tmp_path: Path, remote: tuple[Path, str, str]) -> None:
    repo, first, _ = remote
    write(tmp_path / "m.yml", definition(SOLO, "solo", TESTS + "      - file_consistency\n",
                                         compare(repo, commit=first)))
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")
    assert set(statuses(protocol).values()) == {"passed"}, protocol.markdown()
    assert result(protocol, "file_consistency").reason == "all 1 file of the compare model is there"


def test_a_commit_that_does_not_exist_fails_the_compare_tests(tmp_path: Path,
                                                             remote: tuple[Path, str, str]) -> None:
    repo, _, _ = remote
    write(tmp_path / "m.yml", definition(SOLO, "solo", TESTS, compare(repo, commit="0123456789abcdef")))
    sink = Sink()
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work", sink)
    [error] = [d for d in sink.diagnostics if d.code == "E0704"]
    assert error.message.startswith(f"cannot get commit '0123456789abcdef' of compare repository '{repo}'")
    assert (error.span.line, error.span.col) == (13, 5)  # the compare_model mapping
    s = statuses(protocol)
    assert s["compare_link_masses"] == s["compare_masses"] == s["topological_self_consistency"] == "failed"
    assert result(protocol, "compare_masses").reason == f"the compare model cannot be loaded: {error.message}"
