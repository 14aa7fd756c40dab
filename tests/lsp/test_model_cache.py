"""The language server's model cache (compiler/options.py ModelCache) holds values, not parses:
a model's spans are found as it enters, so the parsed XML file behind it is freed; and it is
bounded, forgetting the model used longest ago."""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

from mpc.backends import urdf_reader
from mpc.backends.xml import XmlSource
from mpc.compiler.options import ModelCache
from mpc.core.diagnostics import Sink
from mpc.core.span import LazySpan, Span
from mpc.ir.robot import Robot
from mpc.lsp.analysis import analyse
from mpc.lsp.server import MpcServer
from tests.conftest import write
from tests.lsp.definitions import EXPORT, HEAD

ARM = """<robot name="arm">
  <link name="base"/>
  <link name="upper"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/>
    <child link="upper"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="hand">
    <visual><geometry><box size="1 1 1"/></geometry></visual>
  </link>
  <joint name="wrist" type="fixed">
    <parent link="upper"/>
    <child link="hand"/>
  </joint>
</robot>
"""


def _parses() -> list[XmlSource]:
    gc.collect()
    return [o for o in gc.get_objects() if isinstance(o, XmlSource)]


def test_a_model_entering_the_cache_lets_its_parse_go_and_keeps_its_places(tmp_path: Path) -> None:
    urdf = write(tmp_path / "arm.urdf", ARM)
    parses: list[weakref.ref[XmlSource]] = []

    def reader(sink: Sink) -> Robot | None:
        robot = urdf_reader.read(urdf, sink)
        assert robot is not None
        span = robot.links["upper"].span
        assert type(span) is LazySpan  # the reader's spans are lazy: each holds the parse
        parses.append(weakref.ref(object.__getattribute__(span, "_find")))
        return robot

    robot = ModelCache().read(urdf, (), Sink(), reader)
    gc.collect()
    assert parses and parses[0]() is None, "the parsed file outlives the model's entry in the cache"
    assert robot is not None
    assert robot.links["upper"].span == Span(str(urdf), 3, 3, 3, 8)
    assert robot.joints["shoulder"].span == Span(str(urdf), 4, 3, 4, 9)
    assert robot.links["hand"].visuals[0].span == Span(str(urdf), 10, 5, 10, 12)


def test_the_language_server_keeps_no_parse_of_its_input_models(tmp_path: Path) -> None:
    write(tmp_path / "arm.urdf", ARM)
    path = write(tmp_path / "arm.yml", HEAD + "  joints:\n    shoulder: {eff: 2}\n" + EXPORT)
    server = MpcServer()
    before = len(_parses())
    analysis = analyse(path, path.read_text(encoding="utf-8"), {}, server.options)
    assert analysis.program is not None and not analysis.diagnostics
    assert server.options.models is not None and len(server.options.models) == 1
    assert len(_parses()) == before


def _read_counting(cache: ModelCache, path: Path, reads: list[str]) -> None:
    def reader(sink: Sink) -> Robot | None:
        reads.append(path.name)
        return urdf_reader.read(path, sink)

    assert cache.read(path, (), Sink(), reader) is not None


def test_the_cache_forgets_the_model_used_longest_ago_beyond_its_count(tmp_path: Path) -> None:
    a, b, c = (write(tmp_path / f"{n}.urdf", ARM) for n in "abc")
    cache, reads = ModelCache(most_models=2), []
    for path in (a, b, a, c, a, b):  # a used again before c comes: b is the one to go
        _read_counting(cache, path, reads)
    assert reads == ["a.urdf", "b.urdf", "c.urdf", "b.urdf"]
    assert len(cache) == 2


def test_the_cache_forgets_models_beyond_its_bytes_but_keeps_the_last(tmp_path: Path) -> None:
    a, b = (write(tmp_path / f"{n}.urdf", ARM) for n in "ab")
    big = write(tmp_path / "big.urdf", ARM.replace("</robot>", "<!--" + "x" * 4000 + "--></robot>"))
    cache, reads = ModelCache(most_bytes=2 * len(ARM) + 10), []
    for path in (a, b, a, b):
        _read_counting(cache, path, reads)
    assert reads == ["a.urdf", "b.urdf"] and len(cache) == 2  # both fit
    _read_counting(cache, big, reads)  # larger than the bound alone: kept, the others go
    assert len(cache) == 1
    _read_counting(cache, big, reads)
    _read_counting(cache, a, reads)
    assert reads == ["a.urdf", "b.urdf", "big.urdf", "a.urdf"] and len(cache) == 1
