"""The pool of processes that computes one build's meshes (backends/meshes.py `_compute`):
with it (MPC_MESH_WORKERS=2) a build writes the same bytes as without it, and the meshes
are really computed in other processes: forked from `mpc compile`, or forked from a fork
server once MuJoCo is loaded (its threads must not be copied into a worker).

The rest of the suite builds with MPC_MESH_WORKERS=1 (tests/conftest.py): its tests already
run side by side on every core.
"""

from __future__ import annotations

import filecmp
import os
import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from mpc.backends.meshes import mesh_workers, share_cores
from mpc.core.diagnostics import Sink
from tests.conftest import compile_file, definition, write
from tests.mpc_command import mpc_process

# The ball is fine enough (20,480 triangles) that its job lasts while the pool's other worker
# starts: the plain path (backends/plain_meshes.py) converts the small shapes in a millisecond.
SHAPES = {"box": lambda: trimesh.creation.box((0.1, 0.2, 0.3)),
          "ball": lambda: trimesh.creation.icosphere(5, 0.1),
          "rod": lambda: trimesh.creation.cylinder(0.02, 0.4),
          "cone": lambda: trimesh.creation.cone(0.05, 0.1)}


def _robot(folder: Path, size: float = 1.0) -> Path:
    """Four links, each with its own STL mesh (`size` times the shape): converted to OBJ, they
    are four jobs."""
    links, joints = [], []
    for i, (name, make) in enumerate(SHAPES.items()):
        make().apply_scale(size).export(folder / f"{name}.stl")
        links.append(f'<link name="{name}"><visual><geometry><mesh filename="{name}.stl"/></geometry>'
                     f'</visual></link>')
        if i:
            joints.append(f'<joint name="j{i}" type="fixed"><parent link="box"/><child link="{name}"/>'
                          f'<origin xyz="{i} 0 0"/></joint>')
    write(folder / "shapes.urdf", f'<robot name="shapes">{"".join(links + joints)}</robot>\n')
    return write(folder / "shapes.yml", definition("shapes.urdf", mesh_format="obj", robotname="shapes"))


def _built(folder: Path, workers: str, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, set[int]]:
    """The build's output folder with MPC_MESH_WORKERS=workers (and a cache of its own), and
    the processes that derived its meshes (MPC_CACHE_TRACE's lines: pid, event, name)."""
    monkeypatch.setenv("MPC_MESH_WORKERS", workers)
    monkeypatch.setenv("MPC_CACHE_DIR", str(folder / f"cache-{workers}"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(trace := folder / f"trace-{workers}"))
    sink = Sink()
    result = compile_file(_robot(folder), folder / f"out-{workers}", sink)
    assert result.out is not None and not sink.diagnostics, sink.summary()
    return result.out, {int(line.split()[0]) for line in trace.read_text().splitlines() if " derive " in line}


def _same_tree(a: Path, b: Path) -> None:
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    assert len(files) >= 5 and [p for p in files if not filecmp.cmp(a / p, b / p, shallow=False)] == []


def test_a_pool_writes_what_one_process_writes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import mujoco  # noqa: F401  (loaded: the pool's workers come from a fork server)

    alone, computed_alone = _built(tmp_path, "1", monkeypatch)
    assert computed_alone == {os.getpid()} and len(SHAPES) == 4
    pooled, computed_pooled = _built(tmp_path, "2", monkeypatch)
    assert os.getpid() not in computed_pooled and 1 <= len(computed_pooled) <= 2
    _same_tree(alone, pooled)


def test_mpc_compile_forks_its_pool(tmp_path: Path) -> None:
    """The meshes are derived in the pool's processes, not in `mpc compile`'s own. (One worker
    may take all four small jobs before the other has started: a loaded machine did.)"""
    path = _robot(tmp_path)
    trace = tmp_path / "trace"
    env = {**os.environ, "MPC_MESH_WORKERS": "2", "MPC_CACHE_DIR": str(tmp_path / "cache"),
           "MPC_CACHE_TRACE": str(trace)}
    mpc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "compile", str(path), "-o",
                            str(tmp_path / "out")], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    _, stderr = mpc.communicate(timeout=600)
    assert mpc.returncode == 0, stderr
    derived = [int(line.split()[0]) for line in trace.read_text().splitlines() if " derive " in line]
    assert len(derived) == len(SHAPES) and mpc.pid not in derived and 1 <= len(set(derived)) <= 2
    written = sorted(p.name for p in (tmp_path / "out/meshes/obj").iterdir())
    assert written == sorted(f"{n}.obj" for n in SHAPES)


def test_the_workers_of_a_build(monkeypatch: pytest.MonkeyPatch) -> None:
    cores = len(os.sched_getaffinity(0))
    monkeypatch.delenv("MPC_MESH_WORKERS")
    monkeypatch.setattr("mpc.backends.meshes._share", None)
    assert mesh_workers() == cores
    share_cores(2)  # mpc run -j2
    assert mesh_workers() == max(1, cores // 2)
    for given, used in (("3", 3), ("0", max(1, cores // 2)), ("x", max(1, cores // 2))):
        monkeypatch.setenv("MPC_MESH_WORKERS", given)
        assert mesh_workers() == used


@pytest.mark.parametrize("models", [1, 2])
def test_mpc_run_gives_each_build_its_share_of_the_cores(tmp_path: Path, models: int) -> None:
    """`mpc run -j2`: one model alone computes its meshes on every core (a pool), two side by
    side each on its own share (on two cores: in its worker, one core each)."""
    names = ["a", "b"][:models]
    for size, name in enumerate(names, 1):
        (tmp_path / name).mkdir()
        _robot(tmp_path / name, size)  # meshes of their own: each model converts its own
        # bobj: trimesh's work, which goes to the pool (the plain path's small work stays in the build)
        write(tmp_path / f"{name}.yml", definition(f"{name}/shapes.urdf", mesh_format="bobj", robotname=name))
    listed = "".join(f"    - {name}.yml\n" for name in names)
    write(tmp_path / "pipeline.yml", f"pipeline:\n  root: .\n  model_definitions:\n{listed}")
    env = {k: v for k, v in os.environ.items() if k != "MPC_MESH_WORKERS"}
    env |= {"MPC_CACHE_DIR": str(tmp_path / "cache"), "MPC_CACHE_TRACE": str(trace := tmp_path / "trace")}
    done = mpc_process("run", tmp_path / "pipeline.yml", "-j", "2", env=env)
    assert done.returncode == 0, done.stderr
    derived = [line.split()[0] for line in trace.read_text().splitlines() if " derive " in line]
    cores = len(os.sched_getaffinity(0))
    assert len(derived) == 4 * models
    assert len(set(derived)) == (min(cores, 4) if models == 1 else 2)
