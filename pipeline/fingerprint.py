"""What a model's build depends on → fingerprints; and the files a build read, recorded.

A model's fingerprint hashes: mpc's version (with a hash of its own source files, so an
edited checkout counts as a new version), the definition after inheritance and pipeline
defaults, how packages are found, the parents' fingerprints, and the content of every
file the build read (input models, meshes, submechanism files). Files are compared by
size and modification time first and re-hashed only when those differ, so `touch` alone
rebuilds nothing and a no-op run hashes nothing.

The files a build reads are found with an audit hook on `open` in the worker process
(`ReadRecorder`), so a new reader cannot forget to declare its inputs. Not seen: files
that programs started by `post_processing` read (they are other processes).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import sys
from collections.abc import Iterable
from functools import cache
from pathlib import Path
from typing import Any

from mpc.core.cache import cache_dir
from mpc.core.files import write_atomic

# File types that are code, not inputs: modules imported while building.
_CODE_SUFFIXES = frozenset({".py", ".pyc", ".so", ".pyd", ".pth", ".pyi", ".typed", ".lark"})
_SYSTEM = ("/proc/", "/sys/", "/dev/", "/etc/")


def digest(*parts: str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()


def data_digest(data: Any) -> str:
    """A digest of YAML data, independent of key order in the file."""
    return digest(json.dumps(data, sort_keys=True, separators=(",", ":"), default=str))


def file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


@cache
def mpc_version() -> str:
    """mpc's version and a digest of its source files (compiler, ir, backends, grammar, …)."""
    from mpc.core.version import mpc_version as installed_version

    ver = installed_version()
    files = _source_stats()
    # The digest of the same files (names and status: size, inode, modification and change
    # times) is kept in the cache: a run that changes nothing reads no source file.
    stats = hashlib.sha256(ver.encode())
    for name, _, st in files:
        stats.update(f"{name}\0{st.st_size}\0{st.st_ino}\0{st.st_mtime_ns}\0{st.st_ctime_ns}\0".encode())
    kept = cache_dir("version") / stats.hexdigest()
    with contextlib.suppress(OSError, UnicodeDecodeError):
        known = kept.read_text(encoding="utf-8")
        if re.fullmatch(r"[0-9a-f]{16}", known):
            return f"{ver}+{known}"
    h = hashlib.sha256(ver.encode())
    for name, file, _ in files:
        h.update(name.encode())
        h.update(file.read_bytes())
    with contextlib.suppress(OSError):
        kept.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(kept, h.hexdigest()[:16])
    return f"{ver}+{h.hexdigest()[:16]}"


def source_files() -> list[tuple[str, Path]]:
    """mpc's own source files (Python and grammars), each with its name inside `mpc`."""
    return [(name, file) for name, file, _ in _source_stats()]


def _source_stats() -> list[tuple[str, Path, os.stat_result]]:
    """mpc's own source files, each with its name inside `mpc` and its status, sorted by name.

    The packages are found through the `mpc` namespace, not as the folders next to
    `compiler/`: in a checkout those include tests/, which are not part of mpc.
    """
    import mpc.compiler

    out = []
    packages = _packages(Path(mpc.compiler.__file__).resolve().parent.parent)
    for name in sorted(packages):
        todo = [(packages[name], name)]
        while todo:
            folder, prefix = todo.pop()
            with os.scandir(folder) as entries:
                for entry in entries:
                    if entry.is_dir(follow_symlinks=False):
                        if entry.name != "__pycache__":
                            todo.append((entry.path, f"{prefix}/{entry.name}"))
                    elif entry.name.endswith((".py", ".lark")) and entry.is_file():
                        out.append((f"{prefix}/{entry.name}", Path(entry.path), entry.stat()))
    return sorted(out, key=lambda item: item[0])


def _packages(top: Path) -> dict[str, str]:
    """The subpackages of `mpc` in `top`: its folders that `import mpc.NAME` finds there."""
    import importlib.util

    out = {}
    with os.scandir(top) as entries:
        for entry in entries:
            if not (entry.is_dir() and entry.name.isidentifier()):
                continue
            spec = importlib.util.find_spec(f"mpc.{entry.name}")
            locations = spec.submodule_search_locations if spec is not None else None
            if locations and Path(next(iter(locations))).resolve() == Path(entry.path).resolve():
                out[entry.name] = entry.path
    return out


MISSING = "missing"  # the digest of a file the build looked for and did not find


def dep_name(path: Path, root: Path) -> str:
    """How the state names a file the build read: relative to the workspace root when it is
    inside it, so a checkout moved or cloned elsewhere keeps its cache; else absolute."""
    return path.relative_to(root).as_posix() if path.is_relative_to(root) else str(path)


def dep_entry(path: Path, root: Path) -> list[Any] | None:
    """[name, size, mtime_ns, sha256] of a file (name: `dep_name`); [name, -1, 0, "missing"]
    when there is no such file (a build that failed on it runs again once it appears); None
    when it cannot be read."""
    name = dep_name(path, root)
    try:
        st = os.stat(path)
        return [name, st.st_size, st.st_mtime_ns, file_digest(path)]
    except FileNotFoundError:
        return [name, -1, 0, MISSING]
    except OSError:
        return None


def deps_current(deps: list[list[Any]], root: Path) -> list[list[Any]] | None:
    """The recorded deps, refreshed where only the time changed; None when a file's content
    changed or the file is gone."""
    out = []
    for name, size, mtime, sha in deps:
        path = root / name  # an absolute name stays as it is
        try:
            st = os.stat(path)
        except OSError:
            if sha == MISSING and not os.path.lexists(path):
                out.append([name, size, mtime, sha])
                continue
            return None
        if sha == MISSING:
            return None
        if st.st_size == size and st.st_mtime_ns == mtime:
            out.append([name, size, mtime, sha])
            continue
        if st.st_size != size:
            return None
        entry = dep_entry(path, root)
        if entry is None or entry[3] != sha:
            return None
        out.append(entry)
    return out


def with_deps(pre: str, deps: Iterable[list[Any]]) -> str:
    """The fingerprint: the part known before building plus the content of what it read."""
    return digest(pre, *(f"{d[0]}\0{d[3]}" for d in sorted(deps)))


class ReadRecorder:
    """Records the files opened for reading in this process (an audit hook; install once per
    worker process, since audit hooks cannot be removed).

    ignore: folders whose files are not inputs (outputs, caches of derived data).
    """

    def __init__(self, ignore: Iterable[Path]) -> None:
        self.ignore = tuple(str(p.resolve()) + os.sep for p in ignore)
        self.read: dict[str, None] = {}
        self.written: set[str] = set()
        # The Python installation holds code; its `share/` folders hold data (robot packages).
        self.code = tuple({os.path.realpath(p) + os.sep for p in (sys.prefix, sys.base_prefix,
                                                                    sys.exec_prefix)})

    def install(self) -> ReadRecorder:
        sys.addaudithook(self._hook)
        return self

    def _hook(self, event: str, args: tuple[Any, ...]) -> None:
        if event != "open":
            return
        path, mode, flags = args[0], args[1], args[2]
        if not isinstance(path, str | os.PathLike):
            return
        text = os.fspath(path)
        if not isinstance(text, str):
            return
        # open() gives a mode; os.open (tempfile, …) gives flags instead.
        writes = (any(c in mode for c in "wax+") if isinstance(mode, str)
                  else isinstance(flags, int) and bool(flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT)))
        if writes:
            self.written.add(os.path.abspath(text))
        else:
            self.read.setdefault(os.path.abspath(text))

    def inputs(self) -> list[Path]:
        """The files read that are inputs of the build (see the filters above)."""
        out = []
        for text in self.read:
            if text in self.written or text.startswith(_SYSTEM) or text.startswith(self.ignore):
                continue
            path = Path(text)
            if path.suffix in _CODE_SUFFIXES or any(p.endswith(".dist-info") or p == "__pycache__"
                                                    for p in path.parts):
                continue
            real = os.path.realpath(text)
            if real.startswith(self.code) and f"{os.sep}share{os.sep}" not in real:
                continue
            if path.is_file() or not path.exists():
                out.append(path)
        return sorted(set(out))
