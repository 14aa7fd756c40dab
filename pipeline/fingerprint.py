"""What a model's build depends on → fingerprints.

A model's fingerprint hashes: mpc's version (with a hash of its own source files, so an
edited checkout counts as a new version: core/version.py `source_version`), the
definition after inheritance and pipeline defaults, how packages are found, the parents'
fingerprints, and the content of every file the build read (input models, meshes,
submechanism files). Files are compared by size and modification time first and re-hashed
only when those differ, so `touch` alone rebuilds nothing and a no-op run hashes nothing.

The files a build reads are found with an audit hook on `open` in the worker process
(core/reads.py `ReadRecorder`), so a new reader cannot forget to declare its inputs.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mpc.core.packages import PackageResolver


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


MISSING = "missing"  # the digest of a file the build looked for and did not find
PACKAGE = -2  # the size of a dep that is a package lookup (`package_entry`), not a file


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


def package_entry(package: str, near: str, found: str | None, root: Path) -> list[Any]:
    """A dep on where a `package://` name was found, as a file's entry is written: [package://NAME,
    then NUL and the folder it was looked up from (dep_name; empty when none), PACKAGE, 0, the
    folder it resolved to (dep_name) or "missing"]. A build depends on which copy of a package
    ROS_PACKAGE_PATH, AMENT_PREFIX_PATH or --package names, not only on the files it read there:
    with another copy named, those files are all unchanged."""
    near_name = dep_name(Path(near), root) if near else ""
    return [f"package://{package}\0{near_name}", PACKAGE, 0,
            dep_name(Path(found), root) if found else MISSING]


def _package_now(name: str, root: Path, resolver: PackageResolver) -> str:
    """Where the package of a `package_entry` named `name` is found now (its last field)."""
    package, _, near = name.removeprefix("package://").partition("\0")
    found = resolver.find(package, root / near if near else None)
    return dep_name(found, root) if found is not None else MISSING


def deps_current(deps: list[list[Any]], root: Path, resolver: PackageResolver) -> list[list[Any]] | None:
    """The recorded deps, refreshed where only the time changed; None when a file's content
    changed or the file is gone, or a package is found elsewhere now (`resolver`: the run's)."""
    out = []
    for name, size, mtime, sha in deps:
        if size == PACKAGE:
            if _package_now(name, root, resolver) != sha:
                return None
            out.append([name, size, mtime, sha])
            continue
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
