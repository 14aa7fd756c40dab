"""Lazy spans (core/span.py): a reader's spans are found when first asked for, and are then
Spans in every way a user relies on: equal, hashed, printed, pickled and copied as one, at the
place the eager span would name."""

from __future__ import annotations

import copy
import dataclasses
import gc
import pickle
import types
import weakref
from pathlib import Path

import pytest

from mpc.backends import sdf_reader, urdf
from mpc.backends.xml import XmlSource
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.span import LazySpan, Span, lazy_span, settle_spans

URDF = b"""<robot name="r">
  <link name="base">
    <visual><geometry><mesh filename="base.stl"/></geometry></visual>
  </link>
  <link name="arm"/>
  <joint name="j" type="fixed">
    <parent link="base"/>
    <child link="arm"/>
  </joint>
  <link
      name="arm"/>
</robot>
"""


class Finder:
    """A finder that counts its calls and can be watched for its release."""

    def __init__(self, span: Span) -> None:
        self.span, self.calls = span, 0

    def __call__(self) -> Span:
        self.calls += 1
        return self.span


def test_a_lazy_span_is_found_once_then_lets_its_finder_go() -> None:
    finder = Finder(Span("a.urdf", 3, 5, 3, 9))
    watch = weakref.ref(finder)
    span = lazy_span("a.urdf", finder)
    assert finder.calls == 0 and span.file == "a.urdf"  # the file needs no finding
    assert (span.line, span.col, span.end_line, span.end_col) == (3, 5, 3, 9)
    assert str(span) == "a.urdf:3:5" and finder.calls == 1
    del finder
    gc.collect()
    assert watch() is None  # with it, the parsed file it holds


def test_a_lazy_span_is_a_span_to_whoever_compares_prints_or_keeps_it() -> None:
    eager = Span("a.urdf", 3, 5, 3, 9)
    lazy = lazy_span("a.urdf", lambda: Span("a.urdf", 3, 5, 3, 9))
    assert isinstance(lazy, Span) and lazy == eager and eager == lazy
    assert hash(lazy) == hash(eager) == hash(("a.urdf", 3, 5, 3, 9))
    assert repr(lazy) == repr(eager) == "Span(file='a.urdf', line=3, col=5, end_line=3, end_col=9)"
    assert lazy != Span("a.urdf", 3, 6, 3, 9) and lazy != lazy_span("b.urdf", lambda: eager)
    assert dataclasses.asdict(lazy) == dataclasses.asdict(eager)
    assert dataclasses.replace(lazy, line=4) == Span("a.urdf", 4, 5, 4, 5)  # ends normalised
    for kept in (pickle.loads(pickle.dumps(lazy_span("a.urdf", lambda: eager))), copy.deepcopy(lazy)):
        assert type(kept) is Span and kept == eager


def test_an_unknown_attribute_is_no_position() -> None:
    span = lazy_span("a.urdf", lambda: Span("a.urdf", 1, 1))
    with pytest.raises(AttributeError, match=r"^colour$"):
        span.colour  # type: ignore[attr-defined]  # noqa: B018


def test_the_urdf_reader_finds_no_span_until_asked_and_then_the_eager_one(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_bytes(URDF.replace(b'  <link\n      name="arm"/>\n', b""))
    robot = urdf.read(path, Sink())
    assert robot is not None
    spans = [robot.span, *(link.span for link in robot.links.values()), robot.joints["j"].span,
             robot.links["base"].visuals[0].span, robot.links["base"].visuals[0].geometry.span]
    assert all(type(s) is LazySpan and "line" not in _set_slots(s) for s in spans)
    src = XmlSource.parse(path.read_bytes(), str(path))
    eager = [src.span(src.root), *(src.span(el) for el in src.root.iter("link")),
             src.span(src.root.find("joint")), src.span(src.root.find("link/visual")),
             src.span(src.root.find(".//mesh"), "filename")]
    assert spans == eager
    assert [(s.line, s.col, s.end_col) for s in spans[1:3]] == [(2, 3, 8), (5, 3, 8)]
    assert (spans[-1].line, spans[-1].col, spans[-1].end_col) == (3, 39, 47)  # base.stl


def test_a_diagnostic_that_names_a_lazy_span_names_its_place(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_bytes(URDF)
    sink = Sink()
    assert urdf.read(path, sink) is None
    (error,) = sink.diagnostics
    assert (error.code, str(error.span), error.message) == ("E0410", f"{path}:11:13", "duplicate link 'arm'")
    ((first, note),) = error.notes
    assert (str(first), note) == (f"{path}:5:3", "link 'arm' is first defined here")


def _set_slots(span: Span) -> set[str]:
    """The slots of `span` that hold a value, looked at without asking for one."""
    return {name for name in ("line", "col", "end_line", "end_col")
            if _has(span, name)}


def _has(span: Span, name: str) -> bool:
    try:
        Span.__dict__[name].__get__(span, Span)
    except AttributeError:
        return False
    return True


def test_a_robot_read_holds_its_parsed_file_no_longer_than_itself(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_bytes(URDF.replace(b'  <link\n      name="arm"/>\n', b""))
    robot = urdf.read(path, Sink())
    assert robot is not None
    source = weakref.ref(object.__getattribute__(robot.links["arm"].span, "_find"))
    gc.collect()
    assert isinstance(source(), XmlSource)  # the spans not yet found hold it
    del robot
    gc.collect()
    assert source() is None


SDF = b"""<sdf version="1.9">
  <model name="m">
    <link name="base"/>
    <link name="arm">
      <pose>0 0 1 0 0 0</pose>
    </link>
    <joint name="j" type="fixed">
      <parent>base</parent>
      <child>arm</child>
    </joint>
  </model>
</sdf>
"""


def test_the_sdf_reader_finds_no_span_until_asked_and_then_the_eager_one(tmp_path: Path) -> None:
    path = tmp_path / "m.sdf"
    path.write_bytes(SDF)
    robot = sdf_reader.read(path, Sink())
    assert robot is not None
    spans = [robot.span, robot.links["base"].span, robot.links["arm"].span, robot.joints["j"].span]
    assert all(type(s) is LazySpan and not _set_slots(s) for s in spans)
    assert [(s.line, s.col, s.end_col) for s in spans] == [(2, 3, 9), (3, 5, 10), (4, 5, 10), (7, 5, 11)]


def test_settle_spans_finds_every_lazy_span_however_nested_and_lets_the_finders_go() -> None:
    finders = [Finder(Span("a.urdf", n, 2, n, 4)) for n in range(1, 6)]
    spans = [lazy_span("a.urdf", f) for f in finders]
    watched = [weakref.ref(f) for f in finders]
    value = {"k": (spans[0], [spans[1]]), "view": types.MappingProxyType({"x": [(spans[2],)]}),
             "record": Diagnostic(Severity.ERROR, "E0414", "m", spans[3], notes=((spans[4], "n"),))}
    del finders
    assert settle_spans(value) == 5 and settle_spans(value) == 0
    gc.collect()
    assert all(w() is None for w in watched)
    assert [(s.line, s.col, s.end_col) for s in spans] == [(n, 2, 4) for n in range(1, 6)]
