"""Where mpc keeps what it can compute again: `$MPC_CACHE_DIR`, else `$XDG_CACHE_HOME/mpc`,
else `~/.cache/mpc`, one folder per kind (git checkouts, meshes); entries that carry the
hash of their bytes, so that a damaged one is never returned; and the lock that lets one
process compute an entry while the others that need it wait for it (`single_flight`)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import threading
import time
from collections.abc import Callable, Iterator
from io import BufferedReader
from pathlib import Path
from typing import Any


def cache_dir(kind: str) -> Path:
    if os.environ.get("MPC_CACHE_DIR"):
        return Path(os.environ["MPC_CACHE_DIR"]) / kind
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "mpc" / kind


# -- verified entries --------------------------------------------------------------------------
# An entry is its file plus `<file>.sha256`, the hash of its bytes, written after it: an entry
# without its hash is unfinished (a killed write) and counts as none (it is written again),
# and one whose bytes do not match it was damaged (a full disk, an edit, a flipped bit) and
# is never returned.

# The files an entry keeps beside it: its hash, and the notes its computation left (a mesh's
# broken DAE references, W0605). They are touched, removed and passed on with the entry.
SIDECARS = (".sha256", ".ignored")
LOCK = ".lock"  # beside an entry of an earlier mpc's cache (its `single_flight`): no part of the entry
BESIDE = (*SIDECARS, LOCK)  # every file that is kept beside an entry and is no entry itself
LOCKS = ".locks"  # in each folder of entries: the file whose bytes `single_flight` locks


def _hash_file(entry: Path) -> Path:
    return entry.with_name(entry.name + ".sha256")


def notes_file(entry: Path) -> Path:
    """Where an entry keeps what its computation ignored, one line each."""
    return entry.with_name(entry.name + ".ignored")


def sidecars(entry: Path) -> list[Path]:
    return [entry.with_name(entry.name + suffix) for suffix in SIDECARS]


def store_entry(entry: Path, data: bytes) -> None:
    """Keep `data` as `entry`, atomically; raises OSError (a read-only cache, a file in the way)."""
    from mpc.core.files import write_atomic

    digest = hashlib.sha256(data).hexdigest()
    write_atomic(entry, data)
    write_atomic(_hash_file(entry), digest + "\n")
    note_written(entry, digest)  # read back by this build: not hashed again


def load_entry(entry: Path) -> tuple[bytes | None, str | None]:
    """(bytes, None) for a sound entry; (None, None) when there is none; (None, why) for an
    entry that must not be used (remove it with `remove_entry`, then compute it again)."""
    data, why, _ = read_entry(entry)
    return data, why


def read_entry(entry: Path) -> tuple[bytes | None, str | None, str]:
    """`load_entry`'s answer, with the SHA-256 (hex) of a sound entry's bytes ("" otherwise)."""
    if not entry.exists() and not entry.is_symlink():
        return None, None, ""
    try:
        if entry.is_symlink() or not entry.is_file():
            return None, "it is not a regular file", ""
        data = entry.read_bytes()
        expected = _hash_file(entry).read_text(encoding="ascii").strip()
        if written_digest(entry) == expected:  # stored by this process, unchanged since
            return data, None, expected
    except FileNotFoundError:  # an unfinished write (or an older mpc's): no entry yet
        return None, None, ""
    except (OSError, UnicodeDecodeError) as e:
        return None, f"it cannot be read ({e})", ""
    if hashlib.sha256(data).hexdigest() != expected:
        return None, "its bytes do not match their hash", ""
    return data, None, expected


def note_written(path: Path, digest: str, origin: Path | None = None) -> None:
    """Remember that `path`, just written by this process, holds bytes of SHA-256 `digest`:
    `written_digest` answers without reading it while it is the same file, unchanged.
    origin: the file `path` is a copy of (a mesh entry of the cache, a source mesh), which a
    kept build names instead of keeping a copy of its own (`written_copy`)."""
    _written[status(os.stat(path))] = digest, origin


def written_digest(path: Path) -> str | None:
    """The SHA-256 noted for `path` (`note_written`) if it is still that file, unchanged (any
    write changes its status time); else None."""
    noted = written_copy(os.stat(path))
    return noted[0] if noted is not None else None


def written_copy(st: os.stat_result) -> tuple[str, Path | None] | None:
    """(the SHA-256, the origin) noted for the file whose status (`os.stat`) is `st`, if that
    file is unchanged since; else None."""
    return _written.get(status(st))


def status(st: os.stat_result) -> tuple[int, int, int, int, int]:
    """A file's identity and status, as git's index keeps them: device, inode, size,
    modification and change times (any write changes the change time)."""
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns


_written: dict[tuple[int, int, int, int, int], tuple[str, Path | None]] = {}


def touch_entry(entry: Path) -> None:
    """Mark an entry (with its sidecars) as used: a CI job passes on the entries its build used
    (`mpc ci job`). A read-only cache still serves."""
    for path in (entry, *sidecars(entry)):
        with contextlib.suppress(OSError):
            os.utime(path)


def remove_entry(entry: Path) -> None:
    """Remove a bad entry and its sidecars; raises OSError when the cache cannot be changed."""
    for path in (entry, *sidecars(entry)):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()


# -- single flight -----------------------------------------------------------------------------
# Two processes (workers of `mpc run`, concurrent `mpc compile`s) that miss the same entry
# would both compute it. Each locks the entry's byte of its folder's `.locks` file first (a
# byte chosen by the entry's name: POSIX record locks, one file for a folder's entries rather
# than a lock file of its own for each, which cost a cold build of a hundred meshes a hundred
# files) and looks again once it holds it: the second finds the first's result. Record locks
# belong to the process: one that dies (killed, crashed) releases its locks with it, and a
# forked child holds none of its parent's. A process keeps a descriptor of each `.locks` file
# open while it holds a lock through it, since closing any descriptor of a file releases every
# record lock the process holds on it; it keeps the last few open after (a build's meshes are
# in one or two folders), and closes those it holds no lock through when it opens more than
# _KEPT_LOCK_FILES: a long-lived process (the language server, a worker of `mpc run`, a test
# run) that meets many caches would otherwise keep a descriptor of each for its life. A
# process holds at most two such locks, always a derived entry's before its source's (in
# another folder), so no two processes wait for each other; two names of one byte (one in two
# billion) only wait for each other.
_lock_files: dict[Path, int] = {}
_locks_held: dict[int, int] = {}  # by descriptor: the locks held (or being taken) through it
_lock_files_guard = threading.Lock()
_KEPT_LOCK_FILES = 8


@contextlib.contextmanager
def single_flight(entry: Path) -> Iterator[None]:
    """Hold the lock of `entry`, waiting while another process holds it. Where no lock can be
    made (a read-only cache, a file in the way) the caller goes on without one: computing the
    entry reports the cache's problem."""
    import fcntl

    name = entry.name.encode(errors="surrogateescape")
    byte = int.from_bytes(hashlib.sha256(name).digest()[:4], "big") >> 1  # below 2**31
    try:
        fd = _lock_file(entry.parent)
    except OSError:
        yield
        return
    try:
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB, 1, byte)
        except (BlockingIOError, PermissionError):  # EAGAIN or EACCES: another process holds it
            trace(f"wait {entry.name}")
            fcntl.lockf(fd, fcntl.LOCK_EX, 1, byte)
    except OSError:
        _let_go(fd)
        yield
        return
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            fcntl.lockf(fd, fcntl.LOCK_UN, 1, byte)
        _let_go(fd)


def _lock_file(folder: Path) -> int:
    """This process's descriptor of `folder`'s `.locks` file, counted as held until `_let_go`."""
    with _lock_files_guard:
        fd = _lock_files.get(folder)
        if fd is None:
            if len(_lock_files) >= _KEPT_LOCK_FILES:
                for kept, idle in [(k, d) for k, d in _lock_files.items() if not _locks_held.get(d)]:
                    del _lock_files[kept]
                    os.close(idle)
            folder.mkdir(parents=True, exist_ok=True)
            fd = _lock_files[folder] = os.open(folder / LOCKS, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        _locks_held[fd] = _locks_held.get(fd, 0) + 1
        return fd


def _let_go(fd: int) -> None:
    with _lock_files_guard:
        _locks_held[fd] -= 1
        if not _locks_held[fd]:
            del _locks_held[fd]


def trace(event: str) -> None:
    """Append `event` (one line) to `$MPC_CACHE_TRACE` when it is set: each computation of an
    entry, so that a test or a user can count them. Silent when the file cannot be written."""
    path = os.environ.get("MPC_CACHE_TRACE")
    if not path:
        return
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, f"{os.getpid()} {event}\n".encode())
        finally:
            os.close(fd)


# -- file digests ------------------------------------------------------------------------------
# A build finds its mesh entries by the hash of each source file, for each export and format.
# The hash is remembered by the file's identity and status (device, inode, size, modification
# and change times to the nanosecond), as git's index does: for the process, and
# in `digests/` for the next ones, so a warm build does not read its meshes to find their
# entries. A file changed since has another status, so another key (an edit that keeps the
# size and the modification time still changes the change time, which no user can set). A
# file modified in the last seconds is not remembered for the next processes: its times may
# not yet show a change made in the same tick of the file system's clock. The file is opened
# all the same, without being read: `mpc run` learns what a build depends on from the files
# it opens (pipeline/fingerprint.py).
#
# What is remembered of the files of one folder is one JSON file, `digests/<hash of the
# folder's path>`: {name: [device, inode, size, mtime, ctime, {what: value}]}, the last status
# seen of each file. A process writes what it learnt when it is done (`keep_digests`; at exit,
# and after each model a worker of `mpc run` builds), each folder's file once: one file per
# mesh made a cold build of a hundred meshes create a hundred files. Two processes that keep
# the same folder at once may lose each other's news, never a value: each merges into what
# the file holds when it writes it.
_digests: dict[tuple[object, ...], str] = {}
_SETTLED_NS = 2_000_000_000
_HEX = frozenset("0123456789abcdef")
Memo = list  # [device, inode, size, mtime, ctime, {what: value}]
_folders: dict[Path, dict[str, Memo]] = {}  # each folder's file, as this process read it
_news: dict[Path, dict[str, Memo]] = {}  # what this process learnt of each folder's files, by file
_keeper: list[int] = []  # the process that registered `keep_digests` at exit


def file_digest(path: Path) -> str:
    """The sha256 (hex) of the file's bytes; raises OSError when it cannot be read."""
    return remembered(path, "", lambda f: hashlib.file_digest(f, "sha256").hexdigest())


def remembered(path: Path, what: str, compute: Callable[[BufferedReader], str], length: int = 64) -> str:
    """`compute(file)`: `length` hex digits made of a file's bytes (`what` names which: "" for
    their sha256), remembered by the file's identity and status as above; raises OSError when
    the file cannot be read. A remembered value of another form is computed again."""
    with open(path, "rb") as f:
        return _remembered_in(f, path, what, compute, length)


def digest_with(path: Path, what: str, suffix: bytes, length: int) -> str:
    """`length` hex digits of the sha256 of the file's bytes followed by `suffix`, remembered as
    `what` (as `remembered` does); the file's own sha256 (`file_digest`) is remembered from the
    same read: the bytes are hashed once for both."""
    def both(f: BufferedReader) -> str:
        own = hashlib.file_digest(f, "sha256")
        _remembered_in(f, path, "", lambda _: own.hexdigest(), 64)
        own.update(suffix)
        return own.hexdigest()[:length]

    with open(path, "rb") as f:
        return _remembered_in(f, path, what, both, length)


def digest_of_read(f: BufferedReader, path: Path, data: bytes) -> str:
    """The sha256 (hex) of `data`, just read whole from `f`, the open file `path`: remembered
    as `file_digest` remembers it, by the status of the file as it is after the read (a write
    during the read changes it), so that a settled file is not hashed again."""
    return _remembered_in(f, path, "", lambda _: hashlib.sha256(data).hexdigest(), 64)


def _remembered_in(f: BufferedReader, path: Path, what: str, compute: Callable[[BufferedReader], str],
                   length: int) -> str:
    st = os.fstat(f.fileno())
    identity = list(status(st))
    key = (*identity, what)
    if key in _digests:
        return _digests[key]
    folder, _, name = os.path.abspath(path).rpartition("/")
    file = _memo_file(folder)
    known = _memo_value(_folder_memos(file).get(name), identity, what)
    if known is not None and len(known) == length and _HEX.issuperset(known):
        _digests[key] = known
        return known
    value = compute(f)
    _digests[key] = value
    if time.time_ns() - max(st.st_mtime_ns, st.st_ctime_ns) > _SETTLED_NS:
        news = _news.setdefault(file, {})
        memo = news.get(name)
        if memo is None or memo[:5] != identity:
            memo = news[name] = [*identity, {}]
        memo[5][what] = value
        if _keeper != [os.getpid()]:
            import atexit

            _keeper[:] = [os.getpid()]
            atexit.register(keep_digests)
    return value


def keep_digests() -> None:
    """Write what this process learnt of its files into `digests/` (a cache that cannot be
    written keeps nothing); a forked process that inherited it writes only its own."""
    from mpc.core.files import write_atomic

    if _keeper != [os.getpid()]:
        _news.clear()
    for file, news in list(_news.items()):
        memos = _read_memos(file)
        for name, memo in news.items():
            old = memos.get(name)
            if type(old) is list and old[:5] == memo[:5] and _is_memo(old):
                memo = [*memo[:5], {**old[5], **memo[5]}]
            memos[name] = memo
        _folders[file] = memos
        with contextlib.suppress(OSError, ValueError):
            write_atomic(file, json.dumps(memos, separators=(",", ":")) + "\n")
    _news.clear()


def _memo_file(folder: str) -> Path:
    return cache_dir("digests") / hashlib.sha256(folder.encode(errors="surrogateescape")).hexdigest()


def _folder_memos(file: Path) -> dict[str, Memo]:
    memos = _folders.get(file)
    if memos is None:
        memos = _folders[file] = _read_memos(file)
    return memos


def _read_memos(file: Path) -> dict[str, Memo]:
    """A folder's file in `digests/`: {} when there is none, or it is not of this form."""
    try:
        memos = json.loads(file.read_bytes())
    except (OSError, ValueError, RecursionError):
        return {}
    return memos if type(memos) is dict else {}


def _is_memo(memo: Any) -> bool:
    return type(memo) is list and len(memo) == 6 and type(memo[5]) is dict


def _memo_value(memo: Any, identity: list[int], what: str) -> str | None:
    """The value remembered for `what` of the file of `identity`, if `memo` (read from a file
    of `digests/`, of any form) holds one."""
    if not _is_memo(memo) or memo[:5] != identity:
        return None
    value = memo[5].get(what)
    return value if type(value) is str else None
