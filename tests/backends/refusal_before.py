"""A frozen copy of PackageResolver.refusal and core/files.py's input_problem as they were before
a plain mesh path took one system call (issue 19): urdf_reader_before.py refuses mesh files with
it, so that tests/backends/test_reader_differential.py compares the new refusal with the old.
A test fixture, never imported by mpc."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path

from mpc.core.files import SPECIAL_ROOTS, describe, package_roots
from mpc.core.packages import PackageResolver


def refusal(resolver: PackageResolver, path: Path, base_dir: Path | None = None) -> str | None:
    """PackageResolver.refusal before (its caches are the resolver's own)."""
    if not path.exists():
        return None
    assert resolver.search_path is not None
    folders = (*resolver.package_map.values(), *resolver.search_path, *resolver.roots,
               *([base_dir] if base_dir else []))
    if folders not in resolver._real_roots:
        resolver._real_roots[folders] = package_roots(folders)
    return input_problem(path, resolver._real_roots[folders], resolver._real_dirs)


def input_problem(path: Path, roots: Iterable[Path], real_dirs: dict[str, str] | None = None) -> str | None:
    real = _realpath(path, real_dirs)
    if any(_within(real, str(s)) for s in SPECIAL_ROOTS):
        return f"it is '{real}', a special file of the system"
    try:
        mode = os.stat(real).st_mode
    except OSError as e:
        return describe(e, "read")
    if not stat.S_ISREG(mode):
        return "it is not a regular file (a device, FIFO, socket or folder)"
    link = real != os.path.normpath(os.path.abspath(path))  # a link on the way
    if link and not any(_within(real, str(r)) for r in roots):
        return f"it is a link to '{real}', outside the model's package roots"
    return None


def _realpath(path: Path, real_dirs: dict[str, str] | None) -> str:
    if real_dirs is None:
        return os.path.realpath(path)
    folder, name = os.path.split(os.path.abspath(path))
    return _resolved(os.path.join(_real_folder(folder, real_dirs), name))


def _real_folder(folder: str, real_dirs: dict[str, str]) -> str:
    real = real_dirs.get(folder)
    if real is None:
        parent, name = os.path.split(folder)
        real = (os.path.realpath(folder) if not name
                else _resolved(os.path.join(_real_folder(parent, real_dirs), name)))
        real_dirs[folder] = real
    return real


def _resolved(joined: str) -> str:
    return os.path.realpath(joined) if os.path.islink(joined) else joined


def _within(real: str, root: str) -> bool:
    return real == root or real.startswith(root if root.endswith("/") else root + "/")
