"""mpc's own version, as its installed distribution records it.

The version is read from the name of the distribution's `.dist-info` folder
(`model_pipeline_compiler-VERSION.dist-info`, as installers name it), found on `sys.path`
in the order Python searches it, as `importlib.metadata` finds it (a stale `.egg-info` left in
the working folder is no installed distribution and is not read); the import of
`importlib.metadata` (e-mail parsing, zip files) costs more than the rest of a run where all
is cached.
`importlib.metadata` is asked only when no such folder is found (an egg, a zip).

`source_version` adds a digest of mpc's own source files to it, for what mpc keeps between
runs (fingerprints, verdicts, build results)."""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import re
import sys
from pathlib import Path

from mpc.core.cache import cache_dir
from mpc.core.files import write_atomic

_DIST = "model_pipeline_compiler"


def mpc_version() -> str:
    found = _from_folder_name()
    if found is not None:
        return found
    from importlib import metadata

    try:
        return metadata.version("model-pipeline-compiler")
    except metadata.PackageNotFoundError:  # running from a source tree that is not installed
        return "unknown"


def _from_folder_name() -> str | None:
    prefix, suffix = f"{_DIST}-", ".dist-info"
    for entry in sys.path:
        try:
            names = os.listdir(entry or ".")
        except OSError:  # not a folder (a zip), or gone
            continue
        for name in names:
            if name.lower().startswith(prefix) and name.endswith(suffix):
                version = name[len(prefix):-len(suffix)]
                if version and "-" not in version and os.path.isfile(os.path.join(entry, name, "METADATA")):
                    return version
    return None


@functools.cache
def source_version() -> str:
    """mpc's version and a digest of its source files (compiler, ir, backends, grammar, …):
    an edited checkout is another mpc, whose builds and verdicts are not those of this one."""
    ver = mpc_version()
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
        with open(file, "rb") as f:
            h.update(f.read())
    with contextlib.suppress(OSError):
        kept.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(kept, h.hexdigest()[:16])
    return f"{ver}+{h.hexdigest()[:16]}"


def source_files() -> list[tuple[str, Path]]:
    """mpc's own source files (Python and grammars), each with its name inside `mpc`."""
    return [(name, Path(file)) for name, file, _ in _source_stats()]


def _source_stats() -> list[tuple[str, str | os.PathLike[str], os.stat_result]]:
    """mpc's own source files, each with its name inside `mpc`, its path and its status, sorted
    by name. Paths are plain strings: every mpc process asks (a Path each took half the walk).

    The packages are found through the `mpc` namespace, not as the folders next to
    `core/`: in a checkout those include tests/, which are not part of mpc.
    """
    out = []
    packages = _packages(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
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
                        out.append((f"{prefix}/{entry.name}", entry.path, entry.stat()))
    return sorted(out, key=lambda item: item[0])


def _packages(top: str) -> dict[str, str]:
    """The subpackages of `mpc` in `top`: its folders that `import mpc.NAME` finds there."""
    import importlib.util

    out = {}
    with os.scandir(top) as entries:
        for entry in entries:
            if not (entry.is_dir() and entry.name.isidentifier()):
                continue
            spec = importlib.util.find_spec(f"mpc.{entry.name}")
            locations = spec.submodule_search_locations if spec is not None else None
            if locations and os.path.realpath(next(iter(locations))) == os.path.realpath(entry.path):
                out[entry.name] = entry.path
    return out
