"""A loaded pipeline file → whether the schema accepts it, remembered across runs.

Validating a pipeline file imports the schema (every node class and its checks), most of the
time of a run where all is cached. A file that the schema accepted without any diagnostic
is remembered by a digest of mpc's version (with the digest of its own sources) and of the
file's data: the same mpc accepts the same data again, the same way, so the next run need
not import the schema. A file with diagnostics is never remembered, so they are shown every
time. A cache that cannot be read or written costs validating, no more. What it does not
do: remember model definitions (building one validates it anyway).
"""

from __future__ import annotations

import contextlib

from mpc.core.cache import cache_dir
from mpc.core.diagnostics import Sink
from mpc.core.version import source_version
from mpc.core.yaml_source import Document
from mpc.pipeline.fingerprint import data_digest


def valid_pipeline(doc: Document, sink: Sink) -> bool:
    """Whether the schema accepts the pipeline file `doc` (its diagnostics go to `sink`)."""
    key = data_digest(["pipeline file", source_version(), doc.data])
    marker = cache_dir("verdicts") / key
    if marker.is_file():
        return True
    from mpc.compiler import schema

    before = len(sink.diagnostics)
    valid = schema.validate_pipeline(doc, sink) is not None
    if valid and len(sink.diagnostics) == before:
        with contextlib.suppress(OSError):
            marker.parent.mkdir(parents=True, exist_ok=True)
            marker.touch()
    return valid
