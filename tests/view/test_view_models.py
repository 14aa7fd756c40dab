"""`mpc view`'s models: a definition compiled in memory or a built folder, the compare model
from a folder or a git repository at a branch or commit, and what it refuses."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import viser

from mpc.cli.view import compare_target, load_model, serve
from mpc.cli.view_scene import link_poses, movable
from mpc.core.diagnostics import Sink
from mpc.ir.kinematics import joint_range
from tests.conftest import definition, write
from tests.fixtures import arm


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


@pytest.mark.parametrize(("text", "git", "branch", "commit"), [
    ("git@host:group/arm.git@main", "git@host:group/arm.git", "main", ""),
    ("https://host/group/arm.git@0123abcd", "https://host/group/arm.git", "", "0123abcd"),
    ("https://host/group/arm.git", "https://host/group/arm.git", "", ""),
    ("ssh://git@host:2222/group/arm.git", "ssh://git@host:2222/group/arm.git", "", ""),
])
def test_compare_addresses(text: str, git: str, branch: str, commit: str) -> None:
    target = compare_target(text)
    assert (target.git, target.branch, target.commit, target.path) == (git, branch, commit, None)


def test_a_definition_and_its_build_show_the_same_robot(tmp_path: Path) -> None:
    arm(tmp_path)
    path = write(tmp_path / "arm.yml", definition(tmp_path / "arm.urdf", robotname="arm"))
    sink = Sink()
    robot = load_model(path, sink)
    assert robot is not None and not sink.has_errors()
    subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(path), "-o",
                    str(tmp_path / "out")], check=True, capture_output=True)
    built = load_model(tmp_path / "out", sink)
    assert built is not None and set(built.links) == set(robot.links)
    names = [j.name for j in movable(robot)]
    assert names == ["shoulder", "elbow"]
    assert joint_range(robot.joints["shoulder"]) == (-1.5, 1.5)
    forearm = robot.joints["elbow"].child
    assert not np.allclose(link_poses(robot, {"shoulder": 0.5})[forearm], link_poses(robot, {})[forearm])


def test_the_compare_model_is_drawn_as_a_ghost(tmp_path: Path) -> None:
    arm(tmp_path)
    path = write(tmp_path / "arm.yml", definition(tmp_path / "arm.urdf", robotname="arm"))
    subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(path), "-o",
                    str(tmp_path / "release")], check=True, capture_output=True)
    sink = Sink()
    robot = load_model(path, sink)
    ghost = load_model(tmp_path / "release", sink)
    assert robot is not None and ghost is not None
    server = serve(robot, ghost, "127.0.0.1", 0, tmp_path / "work", sink)
    try:
        assert isinstance(server, viser.ViserServer) and not sink.diagnostics
        assert server.get_host() == "127.0.0.1" and server.get_port() > 0
    finally:
        server.stop()


def test_what_cannot_be_shown(tmp_path: Path) -> None:
    view = [sys.executable, "-m", "mpc.cli.main", "view"]
    run = subprocess.run([*view, str(tmp_path / "nothing.yml")], capture_output=True, text=True)
    assert run.returncode == 1
    assert f"error[E0690]: '{tmp_path / 'nothing.yml'}' is neither a model definition nor a built folder" \
        in run.stdout + run.stderr
    (tmp_path / "empty").mkdir()
    run = subprocess.run([*view, str(tmp_path / "empty")], capture_output=True, text=True)
    assert run.returncode == 1 and "error[E0690]: cannot show" in run.stdout + run.stderr
    arm(tmp_path)
    path = write(tmp_path / "arm.yml", definition(tmp_path / "arm.urdf", robotname="arm"))
    run = subprocess.run([*view, str(path), "--compare", str(tmp_path / "no-such-repo.git") + "@main"],
                         capture_output=True, text=True)
    assert run.returncode == 1 and "error[E0691]: cannot show" in run.stdout + run.stderr
