"""A release that Phobos CI deployed (its layout: urdf/, smurf/ with JSON-formatted annotation
files, joint_limits.yml, the PDF, README.md, manifest.xml) in a real git repository is the
compare model of a team's first `mpc test`: its SMURF is read with every annotation (the
cut joint and the submechanism close the loop in Pinocchio), and every test passes,
file_consistency included, since mpc writes the files Phobos writes."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import git

from tests.checks.helpers import EVERY_TEST, definition, result, run, statuses
from tests.phobos_release import write_release

TESTS = EVERY_TEST + """\
      - total_mass: 11.0
      - hyrodynChecks:
          - compare_link_positions: [rocker_tip, coupler_tip]
      - file_consistency
      - topological_self_consistency
      - physical_validity
"""
EXPORTS = "    - {type: joint_limits}\n    - {type: pdf}\n"


def released(tmp_path: Path) -> Path:
    """A bare repository whose master holds the Phobos release."""
    bare = tmp_path / "fourbar.git"
    git.Repo.init(bare, bare=True, initial_branch="master")
    work = git.Repo.clone_from(str(bare), tmp_path / "clone")
    write_release(Path(work.working_tree_dir))
    work.git.add(all=True)
    work.index.commit("release 1.0.0 (Phobos CI)")
    work.remote().push("master")
    shutil.rmtree(tmp_path / "clone")
    return bare


def test_first_mpc_test_against_the_last_phobos_release_passes(tmp_path: Path) -> None:
    bare = released(tmp_path)
    smurf = write_release(tmp_path / "input")  # the model itself did not change
    compare = f"      git: {bare}\n      branch: master\n      model_in_repo: smurf/fourbar.smurf\n"
    spec = tmp_path / "m.yml"
    spec.write_text(definition(smurf, "fourbar", TESTS, compare, exports=EXPORTS))
    protocol = run(spec, tmp_path / "out", tmp_path / "work")
    s = statuses(protocol)
    assert set(s.values()) == {"passed"}, protocol.markdown()
    assert {"compare_torques", "compare_com", "file_consistency", "topological_self_consistency",
            "compare_link_positions", "total_mass"} <= s.keys()
    # Every file of the release is written again (README.md, manifest.xml, PDFs aside).
    release = sorted(str(p.relative_to(tmp_path / "input")) for p in (tmp_path / "input").rglob("*")
                     if p.is_file() and p.suffix not in (".pdf", ".md", ".xml"))
    reason = result(protocol, "file_consistency").reason
    assert reason == f"all {len(release)} files of the compare model are there"
    assert result(protocol, "compare_torques").reason.startswith("1 joint torques with 1 loop closure")


def test_the_loop_closure_of_the_compare_model_comes_from_its_smurf(tmp_path: Path) -> None:
    """Without the cut joint in the release's SMURF, the compare model is an open chain whose
    crank holds less: compare_torques sees it (so the passing test above read the loop)."""
    bare = released(tmp_path)
    work = git.Repo.clone_from(str(bare), tmp_path / "edit")
    joints = Path(work.working_tree_dir) / "smurf/fourbar_joints.yml"
    data = json.loads(joints.read_text())
    data["joints"] = [j for j in data["joints"] if not j["cut_joint"]]
    joints.write_text(json.dumps(data, indent=2, sort_keys=True))
    work.index.add(["smurf/fourbar_joints.yml"])
    work.index.commit("the loop forgotten")
    work.remote().push("master")
    smurf = write_release(tmp_path / "input")
    compare = f"      git: {bare}\n      model_in_repo: smurf/fourbar.smurf\n"
    spec = tmp_path / "m.yml"
    spec.write_text(definition(smurf, "fourbar", "      - hyrodynChecks: [compare_torques]\n", compare))
    protocol = run(spec, tmp_path / "out", tmp_path / "work")
    assert statuses(protocol)["compare_torques"] == "failed", protocol.markdown()
