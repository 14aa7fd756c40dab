"""How to compile (`Options`): where outputs go, how packages are found, and what a long-lived
process keeps between compilations (`ModelCache`). Imports no IR: the options are made before
anything is read, and a compilation that its build cache serves reads no model."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.core.diagnostics import Diagnostic, Sink
from mpc.core.files import resolved
from mpc.core.packages import PackageResolver
from mpc.core.record import record

if TYPE_CHECKING:
    from mpc.core import yaml_source as source
    from mpc.ir.robot import Robot


@record(frozen=False)
class Options:
    """How to compile: where outputs go, how packages are found."""

    out: Path | None = None
    resolver: PackageResolver = field(default_factory=PackageResolver)
    # Pipeline runs (pipeline/): the pipeline's defaults, applied to each definition
    # after its own defaults chain; and where the output goes once the runner moves it from
    # `out` (a staging folder) into place, which post_processing commands see as their target.
    defaults: Callable[[source.Document], source.Document] | None = None
    target: Path | None = None
    # A long-lived process (`mpc lsp`): input models kept across compilations until their file
    # changes. None: each compilation reads its inputs once.
    models: ModelCache | None = None
    # Build anew: the kept build of the definition (compiler/build_cache.py) is not used, and
    # this build is kept in its place.
    force: bool = False
    # Run the definition's post_processing commands (`--no-post-processing`: False).
    post_processing: bool = True


@record(frozen=False)
class ModelCache:
    """Input models read once and kept while their file stays the same (modification time and
    size): a server re-checks a definition on every keystroke without re-reading a URDF.

    Each entry keeps the diagnostics its reading reported, replayed into the sink of every
    compilation that takes it. Only the model file itself is watched, not what a xacro includes.

    What is kept is values, not parses: a model's spans are found as it enters (core/span.py:
    settle_spans), so no parsed file stays alive behind it. The cache is bounded: the models
    used longest ago go once more than `most_models` are kept or their files together exceed
    `most_bytes` (the model used last always stays).
    """

    most_models: int = 64
    most_bytes: int = 32 * 1024 * 1024  # of model files; a model held takes about 3× its file
    _models: OrderedDict[tuple[str, tuple[tuple[str, str], ...]],
                         tuple[tuple[int, int], Robot | None, list[Diagnostic]]] = \
        field(default_factory=OrderedDict)
    _bytes: int = 0

    def read(self, path: Path, xacro_args: tuple[tuple[str, str], ...], sink: Sink,
             reader: Callable[[Sink], Robot | None]) -> Robot | None:
        """The robot of `path`, from the cache or by `reader` (which reports into a sink)."""
        try:
            stat = path.stat()
        except OSError:
            return reader(sink)  # the reader says why
        key, stamp = (str(resolved(path)), xacro_args), (stat.st_mtime_ns, stat.st_size)
        entry = self._models.get(key)
        if entry is None or entry[0] != stamp:
            from mpc.core.span import settle_spans

            own = Sink()
            entry = (stamp, reader(own), own.diagnostics)
            settle_spans(entry)
            self._forget(key)
            self._models[key] = entry
            self._bytes += stamp[1]
            self._bound()
        else:
            self._models.move_to_end(key)
        for diagnostic in entry[2]:
            sink.report(diagnostic)
        return entry[1]

    def __len__(self) -> int:
        return len(self._models)

    def _forget(self, key: tuple[str, tuple[tuple[str, str], ...]]) -> None:
        old = self._models.pop(key, None)
        if old is not None:
            self._bytes -= old[0][1]

    def _bound(self) -> None:
        while len(self._models) > 1 and (len(self._models) > self.most_models
                                         or self._bytes > self.most_bytes):
            self._forget(next(iter(self._models)))
