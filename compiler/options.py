"""How to compile (`Options`): where outputs go, how packages are found, and what a long-lived
process keeps between compilations (`ModelCache`). Imports no IR: the options are made before
anything is read, and a compilation that its build cache serves reads no model."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.core.diagnostics import Diagnostic, Sink
from mpc.core.files import resolved
from mpc.core.packages import PackageResolver

if TYPE_CHECKING:
    from mpc.core import yaml_source as source
    from mpc.ir.robot import Robot


@dataclass
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


@dataclass
class ModelCache:
    """Input models read once and kept while their file stays the same (modification time and
    size): a server re-checks a definition on every keystroke without re-reading a URDF.

    Each entry keeps the diagnostics its reading reported, replayed into the sink of every
    compilation that takes it. Only the model file itself is watched, not what a xacro includes.
    """

    _models: dict[tuple[str, tuple[tuple[str, str], ...]], tuple[tuple[int, int], Robot | None,
                                                                 list[Diagnostic]]] = \
        field(default_factory=dict)

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
            own = Sink()
            entry = self._models[key] = (stamp, reader(own), own.diagnostics)
        for diagnostic in entry[2]:
            sink.report(diagnostic)
        return entry[1]
