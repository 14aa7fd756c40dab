"""The mesh cache computes each entry once across processes, and a warm build stays light.

Two `mpc compile` runs that need the same missing mesh: one converts it, the other waits for
its result (core/cache.py `single_flight`), counted through MPC_CACHE_TRACE. A process that
dies holding the lock does not block the next. A warm build of meshes already in the cache
imports no mesh library.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from mpc.backends.meshes import _cached_path
from mpc.compiler.driver import Options, compile_model
from mpc.core.cache import single_flight
from mpc.core.diagnostics import Sink
from tests.conftest import ERD, compile_file, definition, write
from tests.fixtures import ARM_URDF, tetra_stl

ROOT = Path(__file__).resolve().parents[2]
FOREARM = ERD / "ur_description/meshes/ur5/visual/forearm.dae"
HEAVY = ("trimesh", "scipy", "pinocchio", "mujoco", "manifold3d", "collada")


def _arm(folder: Path) -> Path:
    """A definition whose arm has a real DAE mesh (the UR5's forearm), exported as STL."""
    (folder / "meshes").mkdir(parents=True)
    shutil.copyfile(FOREARM, folder / "meshes/forearm.dae")
    write(folder / "arm.urdf", ARM_URDF.replace("meshes/tetra.stl", "meshes/forearm.dae"))
    return write(folder / "arm.yml", definition("arm.urdf", "stl", "arm"))


def _mpc(spec: Path, out: Path, env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o", str(out)],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def _trace(path: Path) -> list[str]:
    """The mesh cache's events (not the build cache's: compiler/build_cache.py)."""
    lines = path.read_text().splitlines() if path.exists() else []
    return [e for line in lines if (e := line.split(" ", 1)[1]).split()[1:2] != ["build"]]


def test_two_processes_on_the_same_cold_mesh_convert_it_once(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _arm(tmp_path / "model")
    cache, trace = tmp_path / "cache", tmp_path / "trace"
    monkeypatch.setenv("MPC_CACHE_DIR", str(cache))
    env = {**os.environ, "MPC_CACHE_TRACE": str(trace)}
    # The test holds the entry's lock first, so that both builds are certain to meet there.
    entry = _cached_path(tmp_path / "model/meshes/forearm.dae", (), ".stl")
    with single_flight(entry):
        builds = [_mpc(spec, tmp_path / f"out{n}", env) for n in (1, 2)]
        deadline = time.monotonic() + 120
        while _trace(trace).count(f"wait {entry.name}") < 2 and time.monotonic() < deadline:
            assert all(b.poll() is None for b in builds), [b.communicate()[0] for b in builds]
            time.sleep(0.05)
    # both wait: let them go
    for build in builds:
        assert build.wait(120) == 0, build.communicate()[0]
    events = _trace(trace)
    assert events.count(f"wait {entry.name}") == 2
    assert [e for e in events if not e.startswith("wait")] == [
        f"parse forearm.dae {hashlib.sha256(FOREARM.read_bytes()).hexdigest()[:12]}", f"derive {entry.name}"]
    assert (tmp_path / "out1/meshes/stl/forearm.stl").read_bytes() == \
        (tmp_path / "out2/meshes/stl/forearm.stl").read_bytes()


def test_a_process_that_died_holding_the_lock_blocks_nobody(tmp_path: Path) -> None:
    spec = _arm(tmp_path / "model")
    cache, trace = tmp_path / "cache", tmp_path / "trace"
    env = {**os.environ, "MPC_CACHE_DIR": str(cache), "MPC_CACHE_TRACE": str(trace)}
    hold = ("import sys, time\nfrom pathlib import Path\nfrom mpc.backends.meshes import _cached_path\n"
            "from mpc.core.cache import single_flight\n"
            "with single_flight(_cached_path(Path(sys.argv[1]), (), '.stl')):\n"
            "    print('locked', flush=True)\n    time.sleep(600)\n")
    holder = subprocess.Popen([sys.executable, "-c", hold, str(tmp_path / "model/meshes/forearm.dae")],
                              env=env, stdout=subprocess.PIPE, text=True)
    assert holder.stdout is not None and holder.stdout.readline() == "locked\n"
    holder.kill()  # killed while holding the lock; the file of the locks stays behind
    holder.wait()
    assert (cache / "meshes" / ".locks").is_file()
    build = _mpc(spec, tmp_path / "out", env)
    assert build.wait(120) == 0, build.communicate()[0]
    assert [e.split()[0] for e in _trace(trace)] == ["parse", "derive"]


def _warm_modules(spec: Path, out: Path, env: dict[str, str]) -> str:
    probe = ("import sys\nfrom mpc.cli.main import main\n"
             "code = main(['compile', sys.argv[1], '-o', sys.argv[2]])\n"
             f"print(code, sorted(m for m in {HEAVY!r} if m in sys.modules))\n")
    done = subprocess.run([sys.executable, "-c", probe, str(spec), str(out)], env=env, capture_output=True,
                          text=True, check=True)
    return done.stdout.splitlines()[-1]


def test_a_warm_build_imports_no_mesh_library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The DAE arm once built (in this process), and the bundled example (STL copied as is)."""
    spec = _arm(tmp_path / "model")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    assert compile_file(spec, tmp_path / "cold", Sink()).out is not None
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}
    assert _warm_modules(spec, tmp_path / "warm", env) == "0 []"
    assert (tmp_path / "warm/meshes/stl/forearm.stl").read_bytes() == \
        (tmp_path / "cold/meshes/stl/forearm.stl").read_bytes()
    assert _warm_modules(ROOT / "examples/talos.yml", tmp_path / "talos", env) == "0 []"


def test_files_with_the_same_bytes_keep_their_own_names(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """An OBJ names its object after the STL file it came from, even when another file with
    the same bytes was parsed first (the normalized form is kept per content and name)."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    tetra_stl(tmp_path / "model/meshes/tetra.stl")
    shutil.copyfile(tmp_path / "model/meshes/tetra.stl", tmp_path / "model/meshes/twin.stl")
    urdf = ARM_URDF.replace("<collision>\n      <geometry><box size=\"0.05 0.05 0.4\"/></geometry>",
                            "<collision>\n      <geometry><mesh filename=\"meshes/twin.stl\"/></geometry>")
    assert "twin.stl" in urdf
    write(tmp_path / "model/arm.urdf", urdf)
    spec = write(tmp_path / "model/arm.yml", definition("arm.urdf", "obj", "arm"))
    assert compile_file(spec, tmp_path / "out", Sink()).out is not None
    for name in ("tetra", "twin"):
        assert f"\no {name}.stl\n" in (tmp_path / f"out/meshes/obj/{name}.obj").read_text()


def test_a_mesh_file_is_parsed_once_for_every_format_and_build(tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """The STL from one plain read of the DAE (backends/plain_meshes.py), the OBJ from one
    trimesh parse; a later build's bobj from none (the parse's normalized form)."""
    spec = _arm(tmp_path / "model")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(tmp_path / "trace"))
    text = spec.read_text()
    spec.write_text(text + "    - {type: urdf, mesh_format: obj, filename_suffix: _obj}\n")
    assert compile_file(spec, tmp_path / "one", Sink()).out is not None
    assert sorted(e.split()[0] for e in _trace(tmp_path / "trace")) == ["derive", "derive", "parse", "parse"]
    spec.write_text(text.replace("mesh_format: stl", "mesh_format: bobj"))
    assert compile_file(spec, tmp_path / "two", Sink()).out is not None
    assert sorted(e.split()[0] for e in _trace(tmp_path / "trace")) == [
        "derive", "derive", "derive", "parse", "parse"]


_OPENED: list[str] | None = None  # the files opened while a test listens (an audit hook cannot be removed)


def _listen(event: str, args: tuple[object, ...]) -> None:
    if _OPENED is not None and event == "open" and isinstance(args[0], str):
        _OPENED.append(args[0])


sys.addaudithook(_listen)


def test_a_remembered_digest_is_given_only_for_the_same_file_status(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Source digests are remembered across processes by the file's status (core/cache.py): a
    process that finds one opens the file (so `mpc run` sees the input) but does not hash it;
    an edit that keeps the size and the modification time is still noticed."""
    global _OPENED
    from mpc.core import cache

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(cache, "_SETTLED_NS", 0)  # remember files written a moment ago too
    mesh = tetra_stl(tmp_path / "tetra.stl")
    first = cache.file_digest(mesh)
    assert first == hashlib.sha256(mesh.read_bytes()).hexdigest()
    cache.keep_digests()  # as the process ends
    assert len(list((tmp_path / "cache/digests").glob("*"))) == 1
    _another_process(monkeypatch)
    monkeypatch.setattr(hashlib, "file_digest", None)  # hashing now fails the test
    _OPENED = []
    try:
        assert cache.file_digest(mesh) == first
        assert str(mesh) in _OPENED
    finally:
        _OPENED = None
    monkeypatch.undo()
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    _another_process(monkeypatch)
    st = os.stat(mesh)
    data = bytearray(mesh.read_bytes())
    data[-1] ^= 1
    while time.time_ns() < st.st_ctime_ns + 20_000_000:  # file times tick coarsely: let one pass
        time.sleep(0.005)
    mesh.write_bytes(bytes(data))
    os.utime(mesh, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert (os.stat(mesh).st_size, os.stat(mesh).st_mtime_ns) == (st.st_size, st.st_mtime_ns)
    assert cache.file_digest(mesh) == hashlib.sha256(bytes(data)).hexdigest() != first


def test_a_file_written_a_moment_ago_is_not_remembered_for_other_processes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Its times may not yet show an edit made in the same tick: each build hashes it again."""
    from mpc.core import cache

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    mesh = tetra_stl(tmp_path / "tetra.stl")
    assert cache.file_digest(mesh) == hashlib.sha256(mesh.read_bytes()).hexdigest()
    cache.keep_digests()
    assert not (tmp_path / "cache/digests").exists()


def _another_process(monkeypatch: pytest.MonkeyPatch) -> None:
    """Forget what this process remembers of its files (core/cache.py), as a new one would."""
    from mpc.core import cache

    for name in ("_digests", "_folders", "_news"):
        monkeypatch.setattr(cache, name, {})


def test_what_a_process_learns_of_its_files_is_kept_once_for_each_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """One file in `digests/` for each folder, merged with what other processes kept there; a
    damaged one is written anew."""
    from mpc.core import cache

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(cache, "_SETTLED_NS", 0)
    meshes = [tetra_stl(tmp_path / folder / f"{name}.stl") for folder in ("a", "b") for name in ("x", "y")]
    digests = [cache.file_digest(mesh) for mesh in meshes[:3]]
    cache.keep_digests()
    memos = sorted((tmp_path / "cache/digests").glob("*"))
    assert len(memos) == 2
    _another_process(monkeypatch)
    assert cache.file_digest(meshes[3]) == digests[0]  # the same bytes
    cache.keep_digests()
    assert sorted(len(json.loads(memo.read_text())) for memo in memos) == [2, 2]  # merged
    for damaged in ("", "[1, 2]", '{"x.stl": [1]}', "{"):
        for memo in memos:
            memo.write_text(damaged)
        _another_process(monkeypatch)
        assert [cache.file_digest(mesh) for mesh in meshes] == [digests[0]] * 4
        cache.keep_digests()
        assert sorted(len(json.loads(memo.read_text())) for memo in memos) == [2, 2]


def _name_digits(path: Path) -> str:
    from mpc.backends.meshes import _digest

    return _digest((path, ()))


def _told_empty(path: Path) -> str:
    from mpc.backends.empty_meshes import has_no_triangles

    return "1" if has_no_triangles(path) else "0"


@pytest.mark.parametrize(("ask", "what", "expected", "other"), [
    (_name_digits, "name ()", lambda mesh: hashlib.sha256(mesh.read_bytes() + b"()").hexdigest()[:10],
     "0123456789"),
    (_told_empty, "no triangles", lambda mesh: "0", "1"),
], ids=["name digits", "no triangles"])
def test_what_a_warm_build_would_read_a_whole_mesh_for_is_remembered(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, ask: Any, what: str, expected: Any,
        other: str) -> None:
    """The ten digits that tell apart meshes of one name, and whether a mesh that is not a binary
    STL holds triangles, are remembered beside its digest (core/cache.py `remembered`), by the
    file's status: the next process gives what is remembered without reading the file, and
    computes again what is remembered in another form. The name's digits are made in the read
    that makes the file's digest (`digest_with`)."""
    from mpc.core import cache

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(cache, "_SETTLED_NS", 0)  # remember files written a moment ago too
    mesh = tmp_path / "tetra.dae"
    mesh.write_bytes(b"<COLLADA><mesh><triangles count='1'><p>0 1 2</p></triangles></mesh></COLLADA>")
    assert ask(mesh) == expected(mesh)
    cache.keep_digests()
    [memo] = (tmp_path / "cache/digests").glob("*")

    if ask is _name_digits:
        assert json.loads(memo.read_text())[mesh.name][5][""] == hashlib.sha256(mesh.read_bytes()).hexdigest()

    def remember(value: str) -> None:
        memos = json.loads(memo.read_text())
        memos[mesh.name][5][what] = value
        memo.write_text(json.dumps(memos))
        _another_process(monkeypatch)

    remember(other)
    assert ask(mesh) == other  # what is remembered: the file is not read again
    for damaged in ("", other + "0", "x" * len(other)):
        remember(damaged)
        assert ask(mesh) == expected(mesh)
        cache.keep_digests()
        assert json.loads(memo.read_text())[mesh.name][5][what] == expected(mesh)


@pytest.mark.parametrize("same_bytes", [True, False])
def test_mesh_files_of_one_name_share_an_output_only_with_the_same_bytes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, same_bytes: bool) -> None:
    """Two folders' `tetra.stl`: one output file when their bytes are equal (known by their
    digests), else each named after its own content."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    tetra_stl(tmp_path / "model/meshes/tetra.stl")
    other = tetra_stl(tmp_path / "model/other/tetra.stl")
    if not same_bytes:
        other.write_bytes(other.read_bytes()[:-1] + b"\1")
    urdf = ARM_URDF.replace("<collision>\n      <geometry><box size=\"0.05 0.05 0.4\"/></geometry>",
                            "<collision>\n      <geometry><mesh filename=\"other/tetra.stl\"/></geometry>")
    write(tmp_path / "model/arm.urdf", urdf)
    spec = write(tmp_path / "model/arm.yml", definition("arm.urdf", "stl", "arm"))
    out = compile_file(spec, tmp_path / "out", Sink()).out
    assert out is not None
    names = sorted(p.name for p in (out / "meshes/stl").iterdir())
    if same_bytes:
        assert names == ["tetra.stl"]
    else:
        digests = [hashlib.sha256(p.read_bytes() + b"()").hexdigest()[:10]
                   for p in (tmp_path / "model/meshes/tetra.stl", other)]
        assert names == sorted(f"tetra_{d}.stl" for d in digests)


def test_a_cold_build_of_the_common_conversions_imports_no_mesh_library(tmp_path: Path) -> None:
    """The UR5 with a mirrored copy (DAE visuals and STL collisions written as STL, mirrored
    or not), built cold with a pool of two processes (forked from the build): no trimesh,
    SciPy or pycollada in the build, and its files are those of the trimesh path
    (tests/fixtures/mesh_output_digests.json, recorded by it)."""
    import json

    from tests.backends.test_mesh_bytes import DEFINITION, DIGESTS, digests

    spec = write(tmp_path / "arms.yml", "".join(
        line for line in DEFINITION.splitlines(keepends=True) if "filename_suffix" not in line))
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache"), "MPC_MESH_WORKERS": "2"}
    assert _warm_modules(spec, tmp_path / "out", env) == "0 []"
    expected = {k: v for k, v in json.loads(DIGESTS.read_text()).items() if k.startswith("meshes/stl/")}
    assert len(expected) == 12
    assert {k: v for k, v in digests(tmp_path / "out").items() if k.startswith("meshes/")} == expected


def test_a_build_whose_meshes_are_cached_imports_no_numpy(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """The DAE arm built once, then its definition edited (so that it is compiled again, not
    taken from the kept build): its mesh comes from the cache; nothing loads numpy (a fleet of
    such builds pays no numpy import each)."""
    spec = _arm(tmp_path / "model")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    assert compile_file(spec, tmp_path / "cold", Sink()).out is not None
    spec.write_text(spec.read_text() + "# edited\n")
    probe = ("import sys\nfrom mpc.cli.main import main\n"
             "code = main(['compile', sys.argv[1], '-o', sys.argv[2]])\n"
             "print(code, sorted(m for m in ('numpy', 'lxml.etree') if m in sys.modules))\n")
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", probe, str(spec), str(tmp_path / "edited")], env=env,
                          capture_output=True, text=True, check=True)
    assert done.stdout.splitlines()[-1].split(" [")[0] == "0"
    assert "numpy" not in done.stdout.splitlines()[-1]


def test_a_noted_digest_holds_only_while_the_file_is_unchanged(tmp_path: Path) -> None:
    """What mpc wrote and knows the digest of (a mesh out of the cache, an entry it stored) is
    not hashed again in the same process (core/cache.py `note_written`), until it changes."""
    from mpc.core import cache

    mesh = tetra_stl(tmp_path / "tetra.stl")
    digest = hashlib.sha256(mesh.read_bytes()).hexdigest()
    cache.note_written(mesh, digest)
    assert cache.written_digest(mesh) == digest
    assert cache.written_digest(tetra_stl(tmp_path / "other.stl")) is None
    st = os.stat(mesh)
    while time.time_ns() < st.st_ctime_ns + 20_000_000:  # file times tick coarsely: let one pass
        time.sleep(0.005)
    data = bytearray(mesh.read_bytes())
    data[-1] ^= 1
    mesh.write_bytes(bytes(data))  # in place: the same file, the same size
    assert cache.written_digest(mesh) is None


def test_a_forced_build_keeps_the_digests_of_what_it_wrote(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """The kept copy of each output, or the mesh entry or source file it names, has the digest
    the entry records: a third build writes them out."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(tmp_path / "trace"))
    spec = _arm(tmp_path / "model")
    time.sleep(0.05)
    for force in (False, True):
        assert compile_model(spec, Sink(), Options(out=tmp_path / "out", force=force)).out is not None

    [entry] = (tmp_path / "cache/builds").glob("*/entry")
    outputs = json.loads(entry.read_bytes().split(b"\n", 1)[0])["outputs"]
    kept = entry.parent / outputs["folder"]
    assert any(name.endswith(".stl") for name, _ in outputs["files"])
    copies = {name: Path(origin) for name, origin in outputs["copies"]}
    assert copies and all(name.endswith(".stl") for name in copies)
    for name, digest in outputs["files"]:
        assert hashlib.sha256(copies.get(name, kept / name).read_bytes()).hexdigest() == digest, name
    assert compile_file(spec, tmp_path / "out2", Sink()).out is not None
    assert (tmp_path / "trace").read_text().splitlines()[-1].endswith("with its outputs")


def _open_lock_files() -> list[str]:
    links = (os.readlink(f"/proc/self/fd/{fd}") for fd in os.listdir("/proc/self/fd")
             if os.path.islink(f"/proc/self/fd/{fd}"))
    return [link for link in links if link.endswith("/.locks") or link.endswith("/.locks (deleted)")]


def test_a_process_meeting_many_caches_keeps_a_few_lock_files_open_and_each_lock_it_holds(
        tmp_path: Path) -> None:
    """A long-lived process (the language server, a fuzz run making a cache per case) kept a
    descriptor of every folder's `.locks` file it ever locked: the fuzz run of 2026-11-27 ran
    out of descriptors. A lock held meanwhile stays held: closing a descriptor of its file
    would release it."""
    before = len(_open_lock_files())
    held = tmp_path / "held/meshes/entry.stl"
    probe = ("import fcntl, os, sys\nfd = os.open(sys.argv[1], os.O_RDWR)\nbyte = int(sys.argv[2])\n"
             "try:\n    fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB, 1, byte)\nexcept OSError:\n"
             "    print('held')\nelse:\n    print('free')\n")
    byte = int.from_bytes(hashlib.sha256(held.name.encode()).digest()[:4], "big") >> 1

    def other_process_sees() -> str:
        return subprocess.run([sys.executable, "-c", probe, str(held.parent / ".locks"), str(byte)],
                              capture_output=True, text=True, check=True).stdout.strip()

    with single_flight(held):
        for n in range(40):
            with single_flight(tmp_path / f"cache{n}/meshes/entry.stl"):
                pass
        assert len(_open_lock_files()) - before <= 8
        assert other_process_sees() == "held"
    assert other_process_sees() == "free"
