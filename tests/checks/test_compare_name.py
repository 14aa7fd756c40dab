"""The protocol names its compare model without the runner's folders (it ends up in a merge
request): relative to the definition's folder inside the project (the git work tree holding
the definition, else its folder), by name outside it, by address without credentials for a
remote repository."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from mpc.checks.compare_name import compare_name
from mpc.core.span import Span
from mpc.ir.program import CompareTarget
from tests.checks.helpers import definition, run, write
from tests.conftest import ERD

SOLO = ERD / "solo_description/robots/solo12.urdf"
TESTS = "      - compare_amount_joints\n"


def released(folder: Path) -> Path:
    """A released solo (its URDF in `folder/urdf/`)."""
    (folder / "urdf").mkdir(parents=True)
    shutil.copy(SOLO, folder / "urdf/solo.urdf")
    return folder


def test_a_compare_folder_elsewhere_in_the_definitions_work_tree_is_shown_relative_to_the_definition(
        tmp_path: Path) -> None:
    project = tmp_path / "project"
    subprocess.run(["git", "init", "-q", str(project)], check=True)
    released(project / "releases/solo")
    write(project / "models/m.yml", definition(SOLO, "solo", TESTS, "      path: ../releases/solo\n"))
    protocol = run(project / "models/m.yml", tmp_path / "out", tmp_path / "work")
    text = protocol.markdown()
    assert "\n\nCompared with `../releases/solo`.\n\n" in text
    assert str(tmp_path) not in text
    assert protocol.to_json()["compare"] == "`../releases/solo`"


def test_a_compare_folder_outside_the_project_is_shown_by_its_name(tmp_path: Path) -> None:
    released(tmp_path / "elsewhere/solo-release")
    write(tmp_path / "project/m.yml",
          definition(SOLO, "solo", TESTS, f"      path: {tmp_path}/elsewhere/solo-release\n"))
    protocol = run(tmp_path / "project/m.yml", tmp_path / "out", tmp_path / "work")
    assert "\n\nCompared with `solo-release (outside the project)`.\n\n" in protocol.markdown()
    assert str(tmp_path) not in protocol.markdown()


def test_a_remote_compare_repository_is_shown_by_its_address_without_credentials(tmp_path: Path) -> None:
    span = Span.of_file(str(tmp_path / "m.yml"))
    for given, shown in (("https://ci:s3cret@git.example.org/robots/solo.git", "https://git.example.org/robots/solo.git"),
                         ("git@git.example.org:robots/solo.git", "git@git.example.org:robots/solo.git"),
                         ("ssh://git@git.example.org/robots/solo.git", "ssh://git@git.example.org/robots/solo.git")):
        assert compare_name(CompareTarget(span=span, git=given), tmp_path / "m.yml") == shown


def test_a_compare_folder_that_cannot_be_loaded_is_named_as_the_protocol_names_it(tmp_path: Path) -> None:
    """The reason a test failed (the compare model cannot be loaded) names the folder as the
    protocol's "Compared with" does, not by the runner's path."""
    subprocess.run(["git", "init", "-q", str(tmp_path / "project")], check=True)
    (tmp_path / "project/releases/empty").mkdir(parents=True)
    for given, shown in (("../releases/missing", "compare model path '../releases/missing' does not exist"),
                         ("../releases/empty", "no model file (urdf/*.urdf, *.urdf, sdf/*.sdf) in "
                                               "'../releases/empty'; name it with model_in_repo")):
        write(tmp_path / "project/models/m.yml", definition(SOLO, "solo", TESTS, f"      path: {given}\n"))
        protocol = run(tmp_path / "project/models/m.yml", tmp_path / "out", tmp_path / "work")
        text = protocol.markdown()
        assert f"the compare model cannot be loaded: {shown}" in text, text
        assert str(tmp_path) not in text
