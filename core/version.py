"""mpc's own version, as its installed distribution records it.

The version is read from the name of the distribution's `.dist-info` folder
(`model_pipeline_compiler-VERSION.dist-info`, as installers name it), found on `sys.path`
in the order Python searches it, as `importlib.metadata` finds it (a stale `.egg-info` left in
the working folder is no installed distribution and is not read); the import of
`importlib.metadata` (e-mail parsing, zip files) costs more than the rest of a run where all
is cached.
`importlib.metadata` is asked only when no such folder is found (an egg, a zip)."""

from __future__ import annotations

import os
import sys

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
