"""`package://`, `file://` and relative filenames (of meshes, models) → files on disk.

The callers build their IR values of what it finds (ir/geometry.py: mesh_source); it knows
no IR.

A package is looked up, in this order, in the package map given by the user
(`--package NAME=DIR`), in ROS_PACKAGE_PATH, in `<prefix>/share` of each prefix of
AMENT_PREFIX_PATH (a sourced ROS 2 workspace), in the `share/` folders of the Python
environment (where pip-installed robot packages such as example-robot-data live,
under `cmeel.prefix/share`), and last among the folders above the model file
(the way PyBullet finds them). Each package name is looked up once.

A package is named as rospack and ament name it, by the `<name>` of its `package.xml`, so a
clone under another name (GitHub's `…-master` archive folder) is found; a folder named
after the package also counts (a package without a package.xml, or a folder name the model's
paths use, as `package://example-robot-data` does). ROS_PACKAGE_PATH's folders are crawled as
rospack crawls them (`crawl`); the share folders hold their packages directly below them.
"""

from __future__ import annotations

import functools
import os
import re
import stat
import sys
import sysconfig
from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.core.reads import note_package
from mpc.core.record import record

if TYPE_CHECKING:
    from collections.abc import Iterable

    from mpc.core.files import Roots


@functools.cache
def interpreter_sites() -> tuple[str, str]:
    """The interpreter's purelib and platlib folders (sysconfig works them out anew on each
    call, 0.2 ms, and every PackageResolver asks)."""
    paths = sysconfig.get_paths()
    return paths["purelib"], paths["platlib"]


def _environment_share_dirs() -> list[Path]:
    return [d for d in _share_dir_candidates(tuple(sys.path), sys.prefix) if d.is_dir()]


@functools.lru_cache(maxsize=8)
def _share_dir_candidates(path: tuple[str, ...], prefix: str) -> tuple[Path, ...]:
    """The share/ folders the Python environment may have (`_environment_share_dirs` keeps
    those that are folders), each once; worked out once per sys.path and prefix, since every
    PackageResolver asks (pathlib's joins took most of a new resolver's time)."""
    # A virtualenv made with --system-site-packages also sees the base installation's packages.
    sites = [*interpreter_sites(), *(p for p in path if p.endswith("-packages"))]
    dirs = [Path(folder) / "cmeel.prefix" / "share" for folder in sites]
    dirs.append(Path(prefix) / "share")
    return tuple(dict.fromkeys(dirs))


_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")
_NAME = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")
_COMMENT = re.compile(rb"<!--.*?-->", re.S)
_MAX_DEPTH = 100  # rospack stops at 1000; no package tree is that deep, a link loop may be


def package_name(folder: Path | str) -> str | None:
    """The `<name>` of `folder/package.xml`, or None (no such file, not a regular file, no
    name in it). Opened without blocking: a FIFO of that name must not hang the lookup."""
    try:
        fd = os.open(os.path.join(folder, "package.xml"), os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        text = os.read(fd, 1 << 16)  # the name comes first; a package.xml is a few kB
    except OSError:
        return None
    finally:
        os.close(fd)
    found = _NAME.search(_COMMENT.sub(b"", text))
    return found.group(1).decode("utf-8", "replace") if found else None


# Crawls and share folders' listings, by the folder's path: once per process (a workspace's
# packages do not move while mpc runs; `mpc check` looks up a few names in each).
_crawls: dict[str, dict[str, Path]] = {}
_shares: dict[str, dict[str, Path]] = {}


def crawl(root: Path) -> dict[str, Path]:
    """Every package under `root` (ROS_PACKAGE_PATH's folders), name → folder, as rospack
    crawls: a folder with a package.xml is a package and is not descended into; a folder
    with CATKIN_IGNORE, COLCON_IGNORE or AMENT_IGNORE is skipped, one with
    `rospack_nosubdirs` not descended into; hidden folders are skipped; links are followed
    (each real folder once). Of two packages with one name, the first in sorted order wins.
    Folders are named as reached (through the links), so a linked package is found where
    the environment names it."""
    key = str(root)
    if key not in _crawls:
        found: dict[str, Path] = {}
        _visit(root, found, set(), 0)
        _crawls[key] = found
    return _crawls[key]


def _visit(folder: Path, found: dict[str, Path], seen: set[str], depth: int) -> None:
    real = os.path.realpath(folder)
    if real in seen or depth > _MAX_DEPTH:
        return
    seen.add(real)
    try:
        with os.scandir(folder) as it:
            entries = sorted(((e.name, e) for e in it), key=lambda pair: pair[0])
    except OSError:
        return
    names = {name for name, _ in entries}
    if any(marker in names for marker in _IGNORE_MARKERS):
        return
    if "package.xml" in names:
        name = package_name(folder)
        if name is not None:
            found.setdefault(name, folder)
            return
    if "rospack_nosubdirs" in names:
        return
    for name, entry in entries:
        try:
            if name.startswith(".") or not entry.is_dir():
                continue
        except OSError:
            continue
        _visit(folder / name, found, seen, depth + 1)


def share_packages(share: Path) -> dict[str, Path]:
    """The packages right below a `share/` folder (an ament prefix's, the Python
    environment's), name (of their package.xml) → folder."""
    key = str(share)
    if key not in _shares:
        found: dict[str, Path] = {}
        try:
            with os.scandir(share) as it:
                folders = sorted(e.name for e in it if not e.name.startswith(".") and e.is_dir())
        except OSError:
            folders = []
        for folder in folders:
            name = package_name(share / folder)
            if name is not None:
                found.setdefault(name, share / folder)
        _shares[key] = found
    return _shares[key]


def package_of(uri: str) -> str | None:
    """The package a `package://NAME/…` filename names, else None."""
    if not uri.startswith("package://"):
        return None
    return uri[len("package://"):].partition("/")[0]


def _path_list(variable: str) -> list[str]:
    return [p for p in os.environ.get(variable, "").split(os.pathsep) if p]


# The folders of a model's files in the layout mpc and Phobos write (`urdf/robot.urdf`,
# `meshes/stl/…`): a file in one may name the files of the folder above (PackageResolver.refusal).
MODEL_FOLDERS = frozenset({"urdf", "sdf", "smurf", "mjcf"})


@record(frozen=False)
class PackageResolver:
    """Finds the folder of a ROS package by name (see the module docstring)."""

    package_map: dict[str, Path] = field(default_factory=dict)
    search_path: list[Path] | None = None
    # Folders, besides the packages, whose files inputs may be: the checkouts of `repo` inputs
    # (compiler/inputs.py adds them) and the workspaces of sourced ROS 2 prefixes.
    roots: list[Path] = field(default_factory=list)
    # The projects of the definitions being compiled (core/files.py: project_root), whose files
    # inputs may be; none when a model file is read on its own (a build's output, a model
    # named on the command line).
    projects: list[Path] = field(default_factory=list)
    _cache: dict[str, Path | None] = field(default_factory=dict)
    _real_roots: dict[tuple[Path, ...], Roots] = field(default_factory=dict)
    _real_dirs: dict[str, str] = field(default_factory=dict)  # the folders of inputs, resolved
    _near: dict[tuple[str, Path], Path | None] = field(default_factory=dict)  # (package, near) → folder
    _named_above: set[Path] = field(default_factory=set)  # packages above a model, by package.xml
    # The search path's folders that are crawled as rospack does (ROS_PACKAGE_PATH's); the
    # others are share/ folders, with their packages right below them.
    _crawled: frozenset[Path] = frozenset()

    def __post_init__(self) -> None:
        if self.search_path is None:
            ros = [Path(p) for p in _path_list("ROS_PACKAGE_PATH")]
            ament = [Path(p) / "share" for p in _path_list("AMENT_PREFIX_PATH")]
            self.search_path = ros + ament + _environment_share_dirs()
            self._crawled = frozenset(ros)
            # colcon's --symlink-install links a workspace's install/ into its src/ and build/:
            # inputs may link anywhere inside the workspace of a sourced prefix.
            for prefix in map(Path, _path_list("AMENT_PREFIX_PATH")):
                install = next((p for p in (prefix, *prefix.parents) if p.name == "install"), None)
                if install is not None:
                    self.add_root(install.parent)

    def find(self, package: str, near: Path | None = None) -> Path | None:
        """The folder of `package`, or None (noted for what records the build's inputs:
        core/reads.py)."""
        found = self._find(package, near)
        note_package(package, near, found)
        return found

    def _find(self, package: str, near: Path | None) -> Path | None:
        if package in self.package_map:
            return self.package_map[package]
        if package not in self._cache:
            self._cache[package] = self._search(package)
        found = self._cache[package]
        if found is None and near is not None:
            key = (package, near)
            if key not in self._near:  # every mesh of a model asks: Path.parents is slow
                self._near[key] = self._above(package, near)
            return self._near[key]
        return found

    def _above(self, package: str, near: Path) -> Path | None:
        """The folder above `near` that is `package`: named so by its package.xml, or by its
        folder's name. One its package.xml names is a package root (the package the model
        lives in, as a `-master` archive unpacks it); one only its folder's name matches is not
        (`package://home/…` from a model under /home must not open the home folders)."""
        for folder in (near, *near.parents):
            if package_name(folder) == package:
                self._named_above.add(folder)
                return folder
            if folder.name == package:
                return folder
        return None

    def _search(self, package: str) -> Path | None:
        """The first folder of the search path that holds `package`: named so by its
        package.xml (crawled for in ROS_PACKAGE_PATH's folders, right below the share/
        folders), else a folder of that name."""
        assert self.search_path is not None
        for root in self.search_path:
            folder = root / package
            if root in self._crawled:
                if package_name(folder) == package:  # the usual layout: no crawl needed
                    return folder
                found = crawl(root).get(package)
            elif folder.is_dir():
                return folder
            else:
                found = share_packages(root).get(package)
            if found is not None:
                return found
            if root.name == package and root.is_dir():
                return root
            if folder.is_dir():
                return folder
        return None

    def add_root(self, folder: Path) -> None:
        if folder not in self.roots:
            self.roots.append(folder)

    def add_project(self, folder: Path) -> None:
        if folder not in self.projects:
            self.projects.append(folder)

    def refusal(self, path: Path, base_dir: Path | None = None) -> str | None:
        """Why the input file `path` (a mesh, a model) must not be read, or None: a file
        outside the projects, the package roots and `base_dir` (the folder of the file naming
        it), a special file (core/files.py: input_problem). A missing file is no refusal:
        whoever reads it reports that.

        A model file read on its own (no project: a build's output, a model named on the
        command line) may also name the files of its model folder: the folder above
        `base_dir` when that is one of the format folders mpc and Phobos write side by side
        (`urdf/`, `sdf/`, `smurf/` beside `meshes/`)."""
        return self._refusal(path, self._package_roots(base_dir))

    def refusals(self, paths: Iterable[Path], base_dir: Path | None = None) -> list[str | None]:
        """`refusal(path, base_dir)` of each of `paths`, with the roots gathered once: the
        meshes of a model, once every package they name has been found."""
        roots = self._package_roots(base_dir)
        return [self._refusal(path, roots) for path in paths]

    def _refusal(self, path: Path, roots: Roots) -> str | None:
        from mpc.core.files import input_problem, plain_stat

        found = plain_stat(path, self._real_dirs)
        if found is False or (found is True and not path.exists()):
            return None
        return input_problem(path, roots, self._real_dirs, None if found is True else found)

    def _package_roots(self, base_dir: Path | None) -> Roots:
        """The package roots and `base_dir`, resolved once for every mesh of a model (their
        folders through the resolved folders of its meshes: `_real_dirs`)."""
        from mpc.core.files import Roots, package_roots

        assert self.search_path is not None
        # A package found on the search path is a root wherever its folder links to: the
        # environment named it, as `--package` names one. One found above the model is a root
        # when its package.xml names it (`_above`).
        found = (*(f for f in self._cache.values() if f is not None), *sorted(self._named_above))
        own = (base_dir, base_dir.parent) if base_dir and not self.projects and base_dir.name in \
            MODEL_FOLDERS else (base_dir,) if base_dir else ()
        folders = (*self.package_map.values(), *self.search_path, *found, *self.roots, *self.projects, *own)
        roots = self._real_roots.get(folders)
        if roots is None:
            roots = self._real_roots[folders] = Roots(package_roots(folders, self._real_dirs))
        return roots

    def resolved(self, path: Path) -> Path:
        """core/files.py `resolved(path)`, through the folders resolved before for this
        resolver's inputs (`_real_dirs`): a model file's folder shares most of its path with
        its meshes' folders and the package roots."""
        from mpc.core.files import real_path

        return Path(real_path(str(path), self._real_dirs))

    def locate(self, uri: str, base_dir: Path) -> tuple[Path | None, str]:
        """A filename as written in a file in `base_dir` → (the file, or None when its package
        cannot be found; why not, a sentence for a diagnostic, else "")."""
        package = package_of(uri)
        if package is not None:
            rest = uri[len("package://") + len(package) + 1:]
            folder = self.find(package, base_dir)
            if folder is None:
                return None, (f"package '{package}' was not found (searched the package map, "
                              "ROS_PACKAGE_PATH, AMENT_PREFIX_PATH, the Python environment and the "
                              "folders above the model)")
            return folder / rest, ""
        if uri.startswith("file://"):
            return Path(uri[len("file://"):]), ""
        return base_dir / uri, ""
