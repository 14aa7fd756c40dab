"""Where mpc keeps what it can compute again: `$MPC_CACHE_DIR`, else `$XDG_CACHE_HOME/mpc`,
else `~/.cache/mpc`, one folder per kind (git checkouts, meshes)."""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir(kind: str) -> Path:
    if os.environ.get("MPC_CACHE_DIR"):
        return Path(os.environ["MPC_CACHE_DIR"]) / kind
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "mpc" / kind
