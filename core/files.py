"""Paths and bytes on disk → confined output paths, checked inputs, atomic writes.

The one place that decides where mpc may write (`confined`: under the output root, never
through a link out of it), what it may read (`input_problem`: regular files inside the
project and the package roots, however named, nothing of /proc, /sys or /dev), how it writes
a file (`write_atomic`: all or nothing) and how an OSError reads to a user (`describe`). It
imports nothing of mpc (the ground floor); it reports nothing itself.
"""

from __future__ import annotations

import errno
import os
import shutil
import stat
import tempfile
from collections.abc import Iterable
from pathlib import Path

NAME_BYTES = 255  # the longest file name of Linux's file systems (NAME_MAX), in bytes
SPECIAL_ROOTS = (Path("/proc"), Path("/sys"), Path("/dev"))
_SPECIAL = tuple(map(str, SPECIAL_ROOTS))  # as _within compares them: the roots and what is below
_SPECIAL_BELOW = tuple(f"{root}/" for root in _SPECIAL)


class OutsideOutput(ValueError):
    """A name that would put a file outside the output folder."""


class NotAFileName(OutsideOutput):
    """A name from the model (a link's, a pose's) that cannot be one file name in the output."""


def name_problem(name: str, *, folders: bool = False) -> str | None:
    """Why `name` cannot be a file name inside the output folder, or None.

    folders: `a/b` is allowed (a relative path of several names), `..` never is.
    """
    if not name:
        return "it is empty"
    if "\0" in name:
        return "it holds a NUL character"
    if name.startswith("/") or (len(name) > 1 and name[1] == ":"):
        return "it is an absolute path"
    parts = name.split("/")
    if not folders and (len(parts) > 1 or "\\" in name):
        return "it holds a '/' or '\\' (a file name, not a path)"
    if "\\" in name:
        return "it holds a '\\'"
    for part in parts:
        if part in (".", ".."):
            return f"it holds '{part}', which names a folder outside the file's own"
        if not part and folders:
            return "it holds an empty folder name ('//' or a '/' at the end)"
        if len(part.encode("utf-8", "surrogatepass")) > NAME_BYTES:
            return f"a name of {len(part.encode('utf-8', 'surrogatepass'))} bytes; file systems take " \
                   f"at most {NAME_BYTES}"
    return None


def confined_files(root: Path, names: Iterable[str]) -> dict[str, Path]:
    """`confined(root, name)` of each name (a relative path), each folder resolved once: a
    plain file name in a folder inside `root` is inside it too unless it is a link (which, and
    any other name, `confined` judges). A build writes a hundred meshes into two folders, and
    each `confined` resolves every folder of the path from `/` (ten system calls)."""
    folders: dict[str, Path | None] = {"": root}
    paths: dict[str, Path] = {}
    for name in names:
        folder, _, base = name.rpartition("/")
        path = None
        if not name_problem(name, folders=True):  # no `..`, `.`, `//`, nor an absolute path
            if folder not in folders:
                try:
                    folders[folder] = confined(root, folder)
                except OutsideOutput:
                    folders[folder] = None  # said for the file's own name (below)
            inside = folders[folder]
            path = inside / base if inside is not None and not os.path.islink(inside / base) else None
        paths[name] = path if path is not None else confined(root, name)
    return paths


def file_name(name: str, what: str) -> str:
    """`name`, a name taken from the model (`what`: 'link', 'pose'), as one file name inside
    the output; raises NotAFileName when it is not one (a '/', '..', an absolute path…).

    Every output path a backend builds from data passes its data through this and the whole
    path through `confined` (tests/backends/test_output_paths.py lists the places)."""
    if why := name_problem(name):
        raise NotAFileName(f"the {what} name '{name}' cannot be a file name: {why}")
    return name


def confined(root: Path, *names: str) -> Path:
    """`root / names…`, which must stay inside `root` once links are followed; raises
    OutsideOutput when a name is absolute, climbs out with `..`, or a link on the way
    (a folder a command made, say) leads out."""
    path = root.joinpath(*names)
    for name in names:
        if Path(name).is_absolute() or ".." in Path(name).parts:
            raise OutsideOutput(f"'{name}' leads out of the output folder")
    real_root = resolved(root)
    real = resolved(path)
    if real != real_root and real_root not in real.parents:
        raise OutsideOutput(f"'{path}' resolves to '{real}', outside the output folder")
    return path


def resolved(path: Path | str) -> Path:
    """`Path(path).resolve()` that never raises: Python 3.11's raises RuntimeError on a
    symlink loop, where this returns the path resolved as far as the loop (os.path.realpath),
    so that reading it fails with an OSError (ELOOP) its reader reports against the input
    that named it."""
    return Path(os.path.realpath(path))


def why_absent(path: Path | str) -> str:
    """Why a file that is not there is not: "does not exist", or that it is a symbolic link
    that loops (Path.is_file and Path.exists say False for both)."""
    try:
        os.stat(path)
    except OSError as e:
        if e.errno == errno.ELOOP:
            return "is a symbolic link that loops (it never reaches a file)"
    return "does not exist"


def package_roots(folders: Iterable[Path], real_dirs: dict[str, str] | None = None) -> tuple[Path, ...]:
    """The folders whose files inputs may link to, resolved (the definitions' folders,
    --package roots, the package search path, a checkout: core/packages.py names them).

    real_dirs: folders resolved before (`input_problem`'s): the roots of a model share most
    of their path with each other and with its meshes' folders, which realpath would look
    at again, component by component, for each."""
    if real_dirs is None:
        return tuple(dict.fromkeys(resolved(f) for f in folders))
    return tuple(dict.fromkeys(Path(real_path(str(f), real_dirs)) for f in folders))


class Roots(tuple[Path, ...]):
    """Resolved package roots (`package_roots`) as `input_problem` asks them, for the many
    files of one model: whether a resolved path is one of them or inside one, by two lookups
    rather than a comparison with each root."""

    _exact: frozenset[str]
    _below: tuple[str, ...]

    def __new__(cls, roots: Iterable[Path]) -> Roots:
        self = super().__new__(cls, roots)
        texts = [str(r) for r in self]
        self._exact = frozenset(texts)
        self._below = tuple(t if t.endswith("/") else t + "/" for t in texts)
        return self

    def hold(self, real: str) -> bool:
        """Whether the resolved path `real` is one of the roots or inside one (`_within`)."""
        return real in self._exact or real.startswith(self._below)


def input_problem(path: Path, roots: Iterable[Path], real_dirs: dict[str, str] | None = None,
                  found: tuple[str, int] | None = None) -> str | None:
    """Why the input file `path` must not be read, or None: the one rule of every file mpc
    reads (a definition's `defaults`, a `derived_base`, a pipeline entry, an input model, a
    mesh, a texture, a xacro include; specs/files.md).

    The file, once links are followed, must lie inside one of `roots` (the project and the
    package roots: `project_root`, core/packages.py), however it is named (a link, an
    absolute path, `../`, `file://`): a mesh at /proc/self/environ or ~/.ssh would otherwise
    be copied into the build and deployed, a `defaults:` file quoted in the log. Whatever the
    roots, devices, FIFOs, sockets and the kernel's /proc, /sys and /dev are refused.

    real_dirs: folders resolved before, kept by the caller for the files of one build (the
    meshes of a model share a few folders). found: what `plain_stat` found for `path`, which
    saves looking again.
    """
    why = _input_problem(path, roots, real_dirs, found)
    if why is not None:
        _refused.add(os.path.realpath(path))
    return why


# The files `input_problem` refused, resolved: no diagnostic quotes a line of them (`quotable`).
_refused: set[str] = set()


def special_problem(path: str | Path) -> str | None:
    """Why `path` (resolved here) is refused wherever it is named: it is of /proc, /sys or
    /dev, the kernel's files, whose content is the process's secrets (its environment)."""
    real = os.path.realpath(path)
    return f"it is '{real}', a special file of the system" if _is_special(real) else None


def _is_special(real: str) -> bool:
    """Whether the resolved path `real` is of /proc, /sys or /dev."""
    return real in _SPECIAL or real.startswith(_SPECIAL_BELOW)


def quotable(file: str) -> bool:
    """Whether a diagnostic may show lines of `file`: a regular file, not of /proc, /sys or
    /dev, that the read rule (`input_problem`) has not refused. A diagnostic whose span lies
    in any other file shows its header line alone, so that no secret reaches a log."""
    real = os.path.realpath(file)
    if _is_special(real) or real in _refused:
        return False
    try:
        return stat.S_ISREG(os.stat(real).st_mode)
    except OSError:
        return False


def _input_problem(path: Path, roots: Iterable[Path], real_dirs: dict[str, str] | None = None,
                   found: tuple[str, int] | None = None) -> str | None:
    """The rule of `input_problem` (which notes what this refuses, for `quotable`)."""
    if found is not None:
        real, mode = found
        normal = str(path)  # plain: already absolute and normal
    else:
        real = _realpath(path, real_dirs)
        normal = ""
    if _is_special(real):
        return f"it is '{real}', a special file of the system"
    if found is None:
        try:
            mode = os.stat(real).st_mode
        except OSError as e:
            return describe(e, "read")
        normal = os.path.normpath(os.path.abspath(path))
    if not stat.S_ISREG(mode):
        return "it is not a regular file (a device, FIFO, socket or folder)"
    if not (roots.hold(real) if isinstance(roots, Roots) else any(_within(real, str(r)) for r in roots)):
        if real != normal:  # a link on the way
            return f"it is a link to '{real}', outside the model's package roots"
        return f"it is '{real}', outside the project and the model's package roots"
    return None


def project_root(folder: Path) -> Path:
    """The project of a definition (or pipeline) file in `folder`: the git work tree holding
    it (the nearest folder above with a `.git`, a folder or a worktree's file), else `folder`
    itself; resolved. Its files are the ones a definition may read besides the packages'."""
    folder = Path(os.path.realpath(folder))
    for candidate in (folder, *folder.parents):
        if os.path.lexists(candidate / ".git"):
            return candidate
    return folder


def plain_stat(path: Path, real_dirs: dict[str, str]) -> tuple[str, int] | bool:
    """What `input_problem` would find for `path` by one system call: (its resolved form, its
    mode) when it is no link; False when there is no such file (Path.exists would say so);
    True when only the long way tells (a link, an error, or a path that is not plain: relative,
    or holding `.`, `..` or `//`).

    Why one call is enough: a plain path's folder resolves as `_realpath` resolves it (kept in
    `real_dirs`); a file there that is no link is its own resolved form, and os.stat of it is
    os.lstat. A model's meshes are plain paths in a few folders: this saves three calls and
    the path arithmetic of each (a large URDF's meshes took 1.5 ms)."""
    text = str(path)
    folder, _, name = text.rpartition("/")
    if (not folder or text[0] != "/" or name in ("", ".", "..") or "/./" in text or "/../" in text
            or "//" in text):
        return True
    real_folder = _real_folder(folder, real_dirs)
    joined = f"{real_folder}/{name}" if real_folder != "/" else f"/{name}"  # os.path.join
    try:
        mode = os.lstat(joined).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return False
    except OSError:
        return True
    return True if stat.S_ISLNK(mode) else (joined, mode)


def real_path(text: str, real_dirs: dict[str, str]) -> str:
    """os.path.realpath(text), through `real_dirs` (`_real_folder`) when `text` is absolute and
    normal (a relative or unusual path, `..` after a link, resolves as realpath resolves it)."""
    if (text[:1] != "/" or "//" in text or "/./" in text or "/../" in text or text.endswith(("/.", "/.."))
            or (text.endswith("/") and text != "/")):
        return os.path.realpath(text)
    return _real_folder(text, real_dirs)


def _realpath(path: Path, real_dirs: dict[str, str] | None) -> str:
    """os.path.realpath(path), its folder's resolved form taken from `real_dirs` when there."""
    if real_dirs is None:
        return os.path.realpath(path)
    folder, name = os.path.split(os.path.abspath(path))
    return _resolved(os.path.join(_real_folder(folder, real_dirs), name))


def _real_folder(folder: str, real_dirs: dict[str, str]) -> str:
    """os.path.realpath of the absolute, normalized `folder`, one component at a time with
    each resolved folder kept in `real_dirs`: a model's meshes lie in a few folders below one
    long path, and realpath would look at each component of it again for every folder."""
    real = real_dirs.get(folder)
    if real is None:
        parent, name = os.path.split(folder)
        real = (os.path.realpath(folder) if not name  # the root: "//" is "/"
                else _resolved(os.path.join(_real_folder(parent, real_dirs), name)))
        real_dirs[folder] = real
    return real


def _resolved(joined: str) -> str:
    """The path `joined`, whose folder is resolved already, with its last component resolved."""
    return os.path.realpath(joined) if os.path.islink(joined) else joined


def _within(real: str, root: str) -> bool:
    """Whether the resolved path `real` is `root` or inside it (both absolute and resolved;
    strings, as Path.parents is slow when every mesh of a model asks)."""
    return real == root or real.startswith(root if root.endswith("/") else root + "/")


def describe(error: OSError, operation: str | None = None) -> str:
    """An OSError as a user reads it: "cannot write '/x/build': Read-only file system"."""
    where = f" '{error.filename}'" if error.filename else ""
    reason = error.strerror or str(error)
    if operation:
        return f"cannot {operation}{where}: {reason}"
    return f"{reason}{':' if where else ''}{where}"


# Errors of writing, not of reading: a copy that fails with one of these failed at its target.
_WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS})


def write_atomic(path: Path, data: str | bytes, *, private: bool = False) -> None:
    """Write `data` to `path` all at once: a reader, or a write that fails half-way (a full
    disk, a kill), never sees a partial file; the previous file stays until the new one is
    complete, and a failed write leaves nothing behind. Raises OSError.

    private: keep mkstemp's 0600 (otherwise the umask's usual mode: state travels as CI
    artifacts)."""
    # Named as the user named them, not as mkdir and the temporary file would.
    if path.is_dir() and not path.is_symlink():
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    blocking = next((p for p in path.parents if p.exists()), None)
    if blocking is not None and not blocking.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(blocking))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:200]}.", suffix=".part", dir=path.parent)
    try:
        if not private:
            os.fchmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


_FICLONE = 0x40049409  # linux/fs.h: _IOW(0x94, 9, int)


def copy_file(source: Path, target: Path) -> None:
    """Make `target` a copy of `source` that shares no storage with it, as a later write into
    either would: a copy-on-write clone where the file system makes one (btrfs, XFS: FICLONE),
    else `copy_file_range` (which a file system may also make a clone of), else a plain copy.
    Never a hard link. Raises OSError; one of writing (a full disk) names `target`, not the
    source as shutil's fast copy does, since the user would look for the problem at the mesh
    they gave rather than at the output."""
    try:
        _copy(source, target)
    except OSError as e:
        if e.errno in _WRITE_ERRORS:
            raise OSError(e.errno, e.strerror, str(target)) from e
        raise


def _copy(source: Path, target: Path) -> None:
    import fcntl

    with open(source, "rb") as src, open(target, "wb") as dst:
        try:
            fcntl.ioctl(dst.fileno(), _FICLONE, src.fileno())
            return
        except OSError:
            pass
        try:
            while os.copy_file_range(src.fileno(), dst.fileno(), 1 << 30):
                pass
            return
        except OSError:  # across file systems on older kernels, or not supported here
            src.seek(0)
            dst.seek(0)
            dst.truncate()
        shutil.copyfileobj(src, dst, 1 << 20)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
