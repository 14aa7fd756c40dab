"""mpc's own version, as its installed distribution records it."""

from __future__ import annotations

from importlib import metadata


def mpc_version() -> str:
    try:
        return metadata.version("model-pipeline-compiler")
    except metadata.PackageNotFoundError:  # running from a source tree that is not installed
        return "unknown"
