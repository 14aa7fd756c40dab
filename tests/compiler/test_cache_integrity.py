"""What a kept build (compiler/build_cache.py) may do to its user: nothing from the cache runs,
and the delivered outputs share no storage with it.

Whoever can write `$MPC_CACHE_DIR` (a CI cache shared with merge-request pipelines) may put
anything there: a pickle that would run code when read, an entry of mpc's own form edited to
lead elsewhere. The next `mpc compile` reads none of it as code, says which entry it refused
(W0650), and builds again. A file delivered by `-o` and the kept copy of it are two files: a
write into one, in place, leaves the other as it was.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from math import inf, nan
from pathlib import Path, PosixPath

import pytest

from mpc.compiler.driver import Options, compile_model
from mpc.compiler.kept_values import BadValue, dumps, loads
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.span import Span
from tests.conftest import definition, write
from tests.fixtures import arm
from tests.mpc_command import mpc


@pytest.fixture
def spec(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The arm's definition (a URDF and an STL mesh)."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    arm(tmp_path / "model")
    spec = write(tmp_path / "model/arm.yml", definition("arm.urdf", mesh_format="stl"))
    time.sleep(0.05)  # past the file system's clock tick: a build of files just written is not kept
    return spec


def _first_build(spec: Path, tmp_path: Path) -> None:
    """Compile into `out1`, keeping the build (in the test itself: the environment of a
    fixture, PYTEST_CURRENT_TEST, is another build's)."""
    assert mpc("compile", spec, "-o", tmp_path / "out1").returncode == 0


def _entry(tmp_path: Path) -> Path:
    (entry,) = (tmp_path / "cache/builds").glob("*/entry")
    return entry


def _replace(entry: Path, data: bytes) -> None:
    """Write `data` as the entry, with the hash beside it that makes it look sound."""
    entry.write_bytes(data)
    entry.with_name("entry.sha256").write_text(hashlib.sha256(data).hexdigest() + "\n")


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _warning(spec: Path, entry: Path, why: str) -> str:
    return (f"{spec}:1:1: warning[W0650]: the kept build '{entry}' is unusable ({why}); it is removed "
            "and the model is built again")


class _Payload:
    """What a pickle runs when it is read: here, it creates the canary file."""

    def __init__(self, canary: Path) -> None:
        self.canary = canary

    def __reduce__(self) -> tuple[object, ...]:
        return open, (str(self.canary), "w")


def test_a_kept_build_crafted_as_a_pickle_runs_nothing_and_is_built_again(
        tmp_path: Path, spec: Path) -> None:
    _first_build(spec, tmp_path)
    entry, canary = _entry(tmp_path), tmp_path / "canary"
    _replace(entry, pickle.dumps({"key": "?", "entry": _Payload(canary)}))
    done = mpc("compile", spec, "-o", tmp_path / "out2")
    err = done.stderr
    assert not canary.exists() and done.returncode == 0
    assert _warning(spec, entry, "it is not a kept build: not JSON") in err
    assert "Traceback" not in err
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")
    assert entry.read_bytes().startswith(b'{"') and not canary.exists()  # built again, and kept
    done = mpc("compile", spec, "-o", tmp_path / "out3")
    assert done.returncode == 0 and "W0650" not in done.stderr


def _retagged(old: bytes, new: bytes) -> Callable[[bytes], bytes]:
    return lambda data: data.replace(old, new, 1)


def _output_outside(data: bytes) -> bytes:
    return data.replace(b'["urdf/robot.urdf"', b'["../../../../../model/arm.urdf"', 1)


@pytest.mark.parametrize(("tamper", "why", "model_read"), [
    (_retagged(b'"mpc.core.span:Span"', b'"os:system"'), "'os:system' names no class of mpc's IR", False),
    (_retagged(b'"mpc.core.span:Span"', b'"mpc.core.span:Path"'),
     "'mpc.core.span:Path' names no class of that module", False),
    (_output_outside, "its output files are not as kept", False),
    (_retagged(b'"form":"mpc kept build 4"', b'"form":"mpc kept build 5"'), "not the header of a kept build",
     False),
    (_retagged(b'{"r":["mpc.ir.program:Program",', b'{"r":["mpc.ir.program:Program",1,'),
     "not one value for each field of 'mpc.ir.program:Program'", True),
    (_retagged(b'{"r":["mpc.ir.program:Program",', b'{"x":["mpc.ir.program:Program",'),
     "an object tagged 'x'", True),
], ids=["another module's class", "a name imported by a module of mpc", "an output outside its folder",
        "another form", "a field too many", "an unknown tag"])
def test_a_tampered_kept_build_is_refused_cleanly_and_built_again(
        tmp_path: Path, spec: Path,
        tamper: Callable[[bytes], bytes], why: str, model_read: bool) -> None:
    _first_build(spec, tmp_path)
    entry = _entry(tmp_path)
    tampered = tamper(entry.read_bytes())
    assert tampered != entry.read_bytes()
    _replace(entry, tampered)
    if model_read:  # the kept outputs are gone: the build takes the kept program and robot
        shutil.rmtree(next(entry.parent.glob("outputs-*")))
    done = mpc("compile", spec, "-o", tmp_path / "out2")
    err = done.stderr
    assert done.returncode == 0
    assert _warning(spec, entry, f"it is not a kept build: {why}") in err
    assert "Traceback" not in err
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")


def test_a_tampered_program_of_a_build_that_wrote_its_kept_outputs_is_built_when_asked_for(
        tmp_path: Path, spec: Path) -> None:
    first = compile_model(spec, Sink(), Options(out=tmp_path / "a", force=True))
    entry = _entry(tmp_path)
    _replace(entry, entry.read_bytes().replace(b'{"r":["mpc.ir.program:Program",', b'{"r":["os:system",', 1))
    again = compile_model(spec, Sink(), Options(out=tmp_path / "b"))
    assert again.out == tmp_path / "b" and _files(tmp_path / "b") == _files(tmp_path / "a")
    assert again.program == first.program and again.robot == first.robot


@pytest.mark.parametrize("kind", ["a link out of the cache", "a FIFO"])
def test_a_kept_output_that_is_no_file_of_the_cache_is_never_delivered(
        tmp_path: Path, spec: Path, kind: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Whoever wrote the entry knows the digest of what they put in the output's place: a
    secret file elsewhere is not read into the outputs, and a FIFO is not waited on (a process
    of its own, which a wait would time out)."""
    monkeypatch.setenv("MPC_CACHE_TRACE", str(tmp_path / "trace"))
    _first_build(spec, tmp_path)
    entry = _entry(tmp_path)
    (kept,) = entry.parent.glob("outputs-*/urdf/robot.urdf")
    secret = write(tmp_path / "secret.txt", "the user's secret")
    kept.unlink()
    if kind == "a FIFO":
        os.mkfifo(kept)
    else:
        kept.symlink_to(secret)
    old = hashlib.sha256((tmp_path / "out1/urdf/robot.urdf").read_bytes()).hexdigest().encode()
    _replace(entry, entry.read_bytes().replace(old, hashlib.sha256(secret.read_bytes()).hexdigest().encode()))
    done = subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o",
                           str(tmp_path / "out2")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")
    events = [" ".join(line.split()[1:3]) for line in (tmp_path / "trace").read_text().splitlines()
              if " build " in line]
    assert events == ["keep build", "reuse build", "keep build"]  # its outputs were refused


# -- delivered outputs are copies --------------------------------------------------------------

def _write_in_place(path: Path, data: bytes) -> None:
    """As an editor that keeps the file's inode writes it: open, truncate, write."""
    with open(path, "r+b") as f:
        f.truncate(0)
        f.write(data)


def test_a_delivered_file_written_in_place_leaves_the_kept_build_and_the_next_delivery_as_they_were(
        tmp_path: Path, spec: Path) -> None:
    _first_build(spec, tmp_path)
    delivered = _files(tmp_path / "out1")
    kept = next(_entry(tmp_path).parent.glob("outputs-*"))
    copied = {"meshes/stl/tetra.stl"}  # a copy of the source mesh: the kept build names it
    assert _files(kept) == {name: data for name, data in delivered.items() if name not in copied}
    for name in delivered:
        _write_in_place(tmp_path / "out1" / name, b"edited")
    assert _files(kept) == {name: data for name, data in delivered.items() if name not in copied}
    assert mpc("compile", spec, "-o", tmp_path / "out2").returncode == 0
    assert _files(tmp_path / "out2") == delivered


def test_a_kept_file_written_in_place_leaves_the_delivered_files_as_they_were(
        tmp_path: Path, spec: Path) -> None:
    _first_build(spec, tmp_path)
    delivered = _files(tmp_path / "out1")
    assert mpc("compile", spec, "-o", tmp_path / "out2").returncode == 0  # delivered from the cache
    kept = next(_entry(tmp_path).parent.glob("outputs-*"))
    for name in _files(kept):
        _write_in_place(kept / name, b"")
    assert _files(tmp_path / "out1") == delivered == _files(tmp_path / "out2")


# -- git's clones in the cache -----------------------------------------------------------------

def _git(cwd: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True,
                   env={**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
                        "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t"})


def test_a_clone_whose_config_would_make_git_run_a_command_is_cloned_again_and_runs_nothing(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    repo, canary = tmp_path / "models", tmp_path / "canary"
    arm(repo)
    for args in (["init", "-q", "-b", "main"], ["add", "-A"], ["commit", "-q", "-m", "arm"]):
        _git(repo, *args)
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm-from-git
          input_models:
            arm: {{repo: {{git: "file://{repo}", branch: main, model_in_repo: arm.urdf}}}}
          assemble: {{model: arm}}
        """)
    assert mpc("compile", spec, "-o", tmp_path / "out1").returncode == 0
    (mirror,) = (tmp_path / "cache/repos").glob("*/mirror.git")
    # A fetch of the branch (every build) would run `touch canary` through git's ext:: transport.
    _git(mirror, "config", "protocol.ext.allow", "always")
    _git(mirror, "config", f"url.ext::sh -c touch% {canary}.insteadOf", f"file://{repo}")
    done = mpc("compile", spec, "-o", tmp_path / "out2")
    err = done.stderr
    assert not canary.exists() and done.returncode == 0
    assert (f"{spec}:5:17: warning[W0650]: the cache's clone '{mirror}' of repository 'file://{repo}' is "
            "unusable (its config sets 'protocol.ext.allow'); it is removed and cloned again") in err
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")
    done = mpc("compile", spec, "-o", tmp_path / "out3")  # the new clone is mpc's
    assert done.returncode == 0 and "W0650" not in done.stderr and not canary.exists()


# -- the form itself -----------------------------------------------------------------------------

def test_kept_values_read_back_as_the_values_written() -> None:
    span = Span("a.yml", 3, 5, 3, 9)
    value = {("x", 1): frozenset({"a", "b"}), "path": PosixPath("meshes/m.stl"), "floats": (0.1, nan, -inf),
             "diagnostic": Diagnostic(Severity.WARNING, "W0401", "m", span, ((None, "n"), (span, "o")), "h"),
             "list": [True, None, 2**70]}
    back = loads(dumps(value))
    floats = back.pop("floats")  # NaN is not equal to itself: compared by its text
    assert type(floats) is tuple and repr(floats) == repr(value.pop("floats"))
    assert back == value and type(back["list"]) is list and back["list"][0] is True
    assert type(back["path"]) is PosixPath and type(back[("x", 1)]) is frozenset


@pytest.mark.parametrize(("text", "why"), [
    (b"[" * 100_000 + b"]" * 100_000, "values nested too deeply"),
    (b'{"d": [[1], 2]}', "an unhashable key of a dict"),
    (b'{"s": [{"d": []}]}', "an unhashable member of a set"),
    (b'{"r": ["mpc.core.span:Span", "a.yml", 1]}', "not one value for each field of 'mpc.core.span:Span'"),
    (b'{"r": ["mpc.core.diagnostics:Severity"]}', "'mpc.core.diagnostics:Severity' is not a record"),
    (b'{"e": ["mpc.core.diagnostics:Severity", "fatal"]}',
     "no member of 'mpc.core.diagnostics:Severity' has the value 'fatal'"),
    (b'{"r": ["mpc.nowhere:X"]}', "'mpc.nowhere:X' names no class of mpc's IR"),
    (b'{"r": ["mpc.ir.nowhere:X"]}', "'mpc.ir.nowhere' is no module of mpc"),
    (b'{"t": [1], "s": [2]}', "an object of 2 members"),
    (b'{"p": 7}', "a path that is no string"),
    (b"\x80\x05K\x01.", "not JSON"),
])
def test_what_kept_values_never_write_is_refused(text: bytes, why: str) -> None:
    with pytest.raises(BadValue) as refused:
        loads(text)
    assert str(refused.value).startswith(why)
