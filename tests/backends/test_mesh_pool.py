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
import time
from pathlib import Path

import pytest
import trimesh

from mpc.compiler.options import Options
from mpc.core.cores import mesh_workers, share_cores
from mpc.core.diagnostics import Sink
from tests.conftest import compile_file, definition, write
from tests.mpc_command import mpc_process

# The ball is fine enough (20,480 triangles) that its job lasts while the pool's other worker
# starts: the plain path (backends/plain_meshes.py) converts the small shapes in a millisecond.
SHAPES = {"box": lambda: trimesh.creation.box((0.1, 0.2, 0.3)),
          "ball": lambda: trimesh.creation.icosphere(5, 0.1),
          "rod": lambda: trimesh.creation.cylinder(0.02, 0.4),
          "cone": lambda: trimesh.creation.cone(0.05, 0.1)}


def _robot(folder: Path, size: float = 1.0, fine: bool = False) -> Path:
    """Four links, each with its own STL mesh (`size` times the shape): converted to OBJ, they
    are four jobs. fine: the ball of 81,920 triangles (4 MB), which a build shares with a
    forked child (backends/mesh_fork.py), not of 20,480 (1 MB)."""
    links, joints = [], []
    for i, (name, make) in enumerate(SHAPES.items()):
        mesh = trimesh.creation.icosphere(6, 0.1) if fine and name == "ball" else make()
        mesh.apply_scale(size).export(folder / f"{name}.stl")
        links.append(f'<link name="{name}"><visual><geometry><mesh filename="{name}.stl"/></geometry>'
                     f'</visual></link>')
        if i:
            joints.append(f'<joint name="j{i}" type="fixed"><parent link="box"/><child link="{name}"/>'
                          f'<origin xyz="{i} 0 0"/></joint>')
    write(folder / "shapes.urdf", f'<robot name="shapes">{"".join(links + joints)}</robot>\n')
    return write(folder / "shapes.yml", definition("shapes.urdf", mesh_format="obj", robotname="shapes"))


def _derivers(trace: Path) -> list[int]:
    """The process of each mesh derived, from MPC_CACHE_TRACE's lines (pid, event, name)."""
    return [int(line.split()[0]) for line in trace.read_text().splitlines() if " derive " in line]


def _built(folder: Path, workers: str | None, monkeypatch: pytest.MonkeyPatch,
           fine: bool = False) -> tuple[Path, set[int]]:
    """The build's output folder with MPC_MESH_WORKERS=workers (None: unset; and a cache of
    its own), and the processes that derived its meshes."""
    if workers is None:
        monkeypatch.delenv("MPC_MESH_WORKERS")
    else:
        monkeypatch.setenv("MPC_MESH_WORKERS", workers)
    monkeypatch.setenv("MPC_CACHE_DIR", str(folder / f"cache-{workers}"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(trace := folder / f"trace-{workers}"))
    sink = Sink()
    result = compile_file(_robot(folder, fine=fine), folder / f"out-{workers}", sink)
    assert result.out is not None and not sink.diagnostics, sink.summary()
    return result.out, set(_derivers(trace))


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


def _two_cores(monkeypatch: pytest.MonkeyPatch) -> None:
    """The build has the machine to itself, of two cores (not one of `mpc run`'s), and has
    loaded no MuJoCo (another test in this process may have: it is unloaded for the test)."""
    monkeypatch.setattr("mpc.core.cores.usable_cores", lambda: 2)
    monkeypatch.setattr("mpc.core.cores._share", None)
    monkeypatch.delitem(sys.modules, "mujoco", raising=False)


def test_a_build_makes_half_its_plain_meshes_in_one_forked_child(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Megabytes of the plain path's jobs (STL → OBJ) on two cores, with no worker started ahead
    (backends/mesh_worker.py): the mesh stage forks a child, and both take jobs from the queue
    (the largest here, the other three in the child); the same bytes as in one process."""
    from mpc.backends import mesh_worker

    alone, computed_alone = _built(tmp_path, "1", monkeypatch, fine=True)
    assert computed_alone == {os.getpid()}
    _two_cores(monkeypatch)
    monkeypatch.setattr(mesh_worker, "start", lambda: None)
    forked, computed = _built(tmp_path, None, monkeypatch, fine=True)
    assert os.getpid() in computed and len(computed) == 2
    _same_tree(alone, forked)


@pytest.mark.parametrize("worker", [True, False], ids=["the worker", "the fork of the mesh stage"])
def test_a_build_makes_the_jobs_of_a_child_that_failed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                       worker: bool) -> None:
    """The worker started as the build starts (backends/mesh_worker.py) is killed at once, or,
    without it, the child forked at the mesh stage (backends/mesh_fork.py) dies at its first
    job: the build makes every mesh itself, the same bytes."""
    import signal

    from mpc.backends import mesh_worker, plain_meshes

    alone, _ = _built(tmp_path, "1", monkeypatch, fine=True)
    _two_cores(monkeypatch)
    start = mesh_worker.start

    def killed() -> None:
        start()
        os.kill(mesh_worker._pid, signal.SIGKILL)

    monkeypatch.setattr(mesh_worker, "start", killed if worker else lambda: None)
    parent, materialise = os.getpid(), plain_meshes.materialise

    def dies_in_the_child(jobs: list[plain_meshes.Job]) -> dict[Path, tuple[str, str]] | None:
        if os.getpid() != parent:
            os._exit(7)
        return materialise(jobs)

    monkeypatch.setattr(plain_meshes, "materialise", dies_in_the_child)
    forked, computed = _built(tmp_path, None, monkeypatch, fine=True)
    assert computed == {parent}
    _same_tree(alone, forked)


def test_the_worker_makes_the_input_models_meshes_and_ends_with_the_build(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The worker is given the conversions the input models' meshes need as soon as the front
    end has read them, makes the costliest first (here the fine ball, 4 MB), and is gone when
    the build returns; the build writes the bytes one process writes. (The build's mesh stage
    waits here until the worker has read the ball: a loaded machine may leave it all to the
    build, which takes what the worker has not begun.)"""
    import time

    from mpc.backends import mesh_worker, meshes

    alone, _ = _built(tmp_path, "1", monkeypatch, fine=True)
    _two_cores(monkeypatch)
    pids: list[int] = []
    start, compute = mesh_worker.start, meshes._compute
    trace = tmp_path / "trace-worker"
    trace.touch()

    def started() -> None:  # asked for twice: as the build starts, and before its front end
        start()
        if mesh_worker._pid not in pids:
            pids.append(mesh_worker._pid)

    def after_the_worker(jobs: list[meshes.Job]) -> dict[Path, tuple[str, str]]:
        deadline = time.monotonic() + 60
        while f"{pids[0]} parse ball.stl" not in trace.read_text() and time.monotonic() < deadline:
            time.sleep(0.01)
        return compute(jobs)

    monkeypatch.setattr(mesh_worker, "start", started)
    monkeypatch.setattr(meshes, "_compute", after_the_worker)
    monkeypatch.delenv("MPC_MESH_WORKERS")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache-worker"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(trace))
    sink = Sink()
    out = compile_file(_robot(tmp_path, fine=True), tmp_path / "out-worker", sink).out
    assert out is not None and not sink.diagnostics, sink.summary()
    [worker] = pids
    parsed = {words[2]: int(words[0]) for words in map(str.split, trace.read_text().splitlines())
              if words[1] == "parse"}  # source → the process that made its entries
    assert parsed["ball.stl"] == worker and set(parsed.values()) <= {worker, os.getpid()}
    assert not mesh_worker.active() and not Path(f"/proc/{worker}").exists()
    _same_tree(alone, out)


def test_a_first_build_starts_the_worker_before_it_looks_for_its_kept_build(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A definition with no kept build starts its worker as the build starts, so that the
    worker imports numpy while the build looks for a kept build and reads the definition. One
    built before starts none until its kept build is found not to hold: its kept outputs are
    most likely all it writes. Each worker is gone when its build returns."""
    from mpc.backends import mesh_worker
    from mpc.compiler.build_cache import KeptBuild

    _two_cores(monkeypatch)
    monkeypatch.delenv("MPC_MESH_WORKERS")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    running: list[bool] = []  # whether a worker ran as each build looked for its kept build
    open_ = KeptBuild.open

    def opened(cls: type[KeptBuild], path: Path, options: Options) -> KeptBuild | None:
        running.append(mesh_worker.active())
        return open_(path, options)

    monkeypatch.setattr(KeptBuild, "open", classmethod(opened))
    spec = _robot(tmp_path, fine=True)
    time.sleep(0.05)  # files changed as a build starts may change after it read them: it is not kept
    for _ in range(2):
        sink = Sink()
        assert compile_file(spec, tmp_path / "out", sink).out is not None, sink.summary()
        assert not mesh_worker.active()
    assert running == [True, False]


def test_a_first_build_encodes_its_kept_model_before_it_makes_meshes_beside_its_worker(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Beside a worker, the build gives it every job of its mesh stage and encodes the model it
    keeps (core/meanwhile.py) before it makes any mesh itself; once, and what it keeps is what a
    build without a worker keeps: the next build takes it and writes the same files."""
    from mpc.backends import mesh_worker, plain_meshes
    from mpc.compiler import build_cache

    events: list[str] = []  # each value encoded for the kept build, each mesh the build made
    dumps, materialise = build_cache.dumps, plain_meshes.materialise
    monkeypatch.setattr(build_cache, "dumps", lambda *a: (events.append("encode"), dumps(*a))[1])
    monkeypatch.setattr(plain_meshes, "materialise",
                        lambda jobs: (events.append("mesh"), materialise(jobs))[1])
    outs = []
    for workers in ("1", None):
        folder = tmp_path / f"workers-{workers}"
        folder.mkdir()
        spec = _robot(folder, fine=True)
        if workers is None:
            _two_cores(monkeypatch)
            monkeypatch.delenv("MPC_MESH_WORKERS")
        monkeypatch.setenv("MPC_CACHE_DIR", str(folder / "cache"))
        time.sleep(0.05)  # files changed as a build starts may change after it read them: it is not kept
        events.clear()
        sink = Sink()
        assert compile_file(spec, folder / "out", sink).out is not None, sink.summary()
        assert not mesh_worker.active()
        # the program and the robot, first beside the worker; after the meshes without one
        assert events[:2] == (["encode", "encode"] if workers is None else ["mesh", "mesh"]), events
        assert events.count("encode") == 3 and events.count("mesh") == 4, events  # (and the diagnostics)
        outs.append(folder / "out")
        events.clear()
        again = compile_file(spec, folder / "again", Sink())  # the kept build, its outputs as they were
        assert again.out is not None and "encode" not in events and "mesh" not in events
        _same_tree(folder / "out", folder / "again")
    _same_tree(*outs)


def test_what_the_forked_child_cannot_make_is_said_as_one_process_says_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A broken STL among the child's jobs (the three smaller meshes; no worker started ahead):
    the build says what it says when one process makes every mesh, word for word."""
    from mpc.backends import mesh_worker

    monkeypatch.setattr(mesh_worker, "start", lambda: None)
    said, derived = [], []
    for workers in ("1", None):
        folder = tmp_path / f"workers-{workers}"
        folder.mkdir()
        spec = _robot(folder, fine=True)
        (folder / "cone.stl").write_bytes(b"no triangles here\n" * 8)
        if workers is None:
            _two_cores(monkeypatch)
            monkeypatch.delenv("MPC_MESH_WORKERS")
        monkeypatch.setenv("MPC_CACHE_DIR", str(folder / "cache"))
        monkeypatch.setenv("MPC_CACHE_TRACE", str(trace := folder / "trace"))
        sink = Sink()
        assert compile_file(spec, folder / "out", sink).out is None
        said.append([(d.code, d.message.replace(str(folder), "FOLDER")) for d in sink.diagnostics])
        derived.append(set(_derivers(trace)))
    assert said[0] == said[1]
    assert [code for code, _ in said[0]] == ["E0603"] and "cone.stl" in said[0][0][1]
    assert len(derived[0]) == 1 and len(derived[1]) == 2


@pytest.mark.parametrize("why", ["a thread runs", "MuJoCo is loaded", "mpc run", "small"])
def test_a_build_forks_no_child_when(why: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Another thread's locks would be copied held into the child, and MuJoCo's GL context;
    `mpc run`'s builds use the other cores for other models; a megabyte of jobs is made here
    sooner than a fork."""
    import threading

    _two_cores(monkeypatch)
    if why == "MuJoCo is loaded":
        import mujoco  # noqa: F401
    if why == "mpc run":
        share_cores(1)
    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    if why == "a thread runs":
        thread.start()
    try:
        _, computed = _built(tmp_path, None, monkeypatch, fine=why != "small")
    finally:
        stop.set()
    assert computed == {os.getpid()}


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
    derived = _derivers(trace)
    assert len(derived) == len(SHAPES) and mpc.pid not in derived and 1 <= len(set(derived)) <= 2
    written = sorted(p.name for p in (tmp_path / "out/meshes/obj").iterdir())
    assert written == sorted(f"{n}.obj" for n in SHAPES)


def test_the_workers_of_a_build(monkeypatch: pytest.MonkeyPatch) -> None:
    cores = len(os.sched_getaffinity(0))
    monkeypatch.delenv("MPC_MESH_WORKERS")
    monkeypatch.setattr("mpc.core.cores._share", None)
    assert mesh_workers() == cores
    share_cores(2)  # mpc run -j2
    assert mesh_workers() == max(1, cores // 2)
    for given, used in (("3", 3), ("0", max(1, cores // 2)), ("x", max(1, cores // 2))):
        monkeypatch.setenv("MPC_MESH_WORKERS", given)
        assert mesh_workers() == used


def test_mpc_compile_makes_its_meshes_in_at_most_one_child_and_prints_what_one_process_prints(
        tmp_path: Path) -> None:
    """As `mpc compile` runs (MPC_MESH_WORKERS unset), on a machine of two cores or more: the
    meshes are made in the build and its worker (backends/mesh_worker.py; on a loaded machine
    the build may make them all), and it prints what one process prints."""
    path = _robot(tmp_path, fine=True)
    printed, derived = [], []
    for workers in ("1", None):
        env = {k: v for k, v in os.environ.items() if k != "MPC_MESH_WORKERS"}
        env |= {"MPC_CACHE_DIR": str(tmp_path / f"cache-{workers}"),
                "MPC_CACHE_TRACE": str(trace := tmp_path / f"trace-{workers}")}
        if workers:
            env["MPC_MESH_WORKERS"] = workers
        mpc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "compile", str(path), "-o",
                                str(tmp_path / f"out-{workers}")], env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
        out, err = mpc.communicate(timeout=600)
        assert mpc.returncode == 0, err
        printed.append((out.replace(f"out-{workers}", "OUT"), err))
        derived.append(set(_derivers(trace)))
    assert printed[0] == printed[1]
    assert len(derived[0]) == 1 and 1 <= len(derived[1]) <= 2
    _same_tree(tmp_path / "out-1", tmp_path / "out-None")


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
    derived = _derivers(trace)
    cores = len(os.sched_getaffinity(0))
    assert len(derived) == 4 * models
    assert len(set(derived)) == (min(cores, 4) if models == 1 else 2)
