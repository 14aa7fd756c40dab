"""Where mpc keeps what it can compute again: `$MPC_CACHE_DIR`, else `$XDG_CACHE_HOME/mpc`,
else `~/.cache/mpc`, one folder per kind (git checkouts, meshes); and entries that carry
the hash of their bytes, so that a damaged one is never returned."""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
from pathlib import Path


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

    write_atomic(entry, data)
    write_atomic(_hash_file(entry), hashlib.sha256(data).hexdigest() + "\n")


def load_entry(entry: Path) -> tuple[bytes | None, str | None]:
    """(bytes, None) for a sound entry; (None, None) when there is none; (None, why) for an
    entry that must not be used (remove it with `remove_entry`, then compute it again)."""
    if not entry.exists() and not entry.is_symlink():
        return None, None
    try:
        if entry.is_symlink() or not entry.is_file():
            return None, "it is not a regular file"
        data = entry.read_bytes()
        expected = _hash_file(entry).read_text(encoding="ascii").strip()
    except FileNotFoundError:  # an unfinished write (or an older mpc's): no entry yet
        return None, None
    except (OSError, UnicodeDecodeError) as e:
        return None, f"it cannot be read ({e})"
    if hashlib.sha256(data).hexdigest() != expected:
        return None, "its bytes do not match their hash"
    return data, None


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
