"""Spans in a minified URDF (its elements on one long line): each element and attribute is
located at its own line and column, as in a pretty-printed file.

The span finder (backends/xml.py) reads a long line's start tags in one scan rather than
searching the line for each element (which made compiling a minified file take time in the
square of its element count: bench/bench_minified.py). The columns below were counted by
hand: `<robot name="r">` is 16 characters, the comment that makes the line long 2007.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.backends import urdf
from mpc.core.diagnostics import Sink
from mpc.core.span import Span, source_line

PAD = "<!--" + "x" * 2000 + "-->"  # 2007 characters: the line is longer than any searched whole
BODY = ('<robot name="r">' + PAD + '<link name="a"/><link name="b"><visual><geometry><box size="1 1 1"/>'
        '</geometry></visual></link><joint name="j" type="{type}"><parent link="a"/><child link="b"/>'
        '</joint></robot>')


def _read(tmp_path: Path, text: str) -> tuple[object, Sink, str]:
    path = tmp_path / "min.urdf"
    path.write_text(text)
    sink = Sink()
    return urdf.read(path, sink), sink, str(path)


@pytest.mark.parametrize("pad", [PAD, ""], ids=["longer than a line searched whole", "short"])
def test_every_element_of_a_minified_urdf_is_located_at_its_own_column(tmp_path: Path, pad: str) -> None:
    shift = len(pad) - len(PAD)
    text = '<?xml version="1.0"?>\n' + BODY.replace(PAD, pad).format(type="fixed")
    robot, sink, file = _read(tmp_path, text)
    assert robot is not None and not sink.diagnostics
    a, b = robot.links["a"], robot.links["b"]  # type: ignore[attr-defined]
    # <link name="a"/> at 16 + 2007 + 1; it is 16 long; <link name="b"> 15, <visual> 8, <geometry> 10,
    # <box …/> 19, </geometry> 11, </visual> 9, </link> 7.
    assert a.span == Span(file, 2, 2024 + shift, 2, 2029 + shift)  # "<" and the name
    assert b.span == Span(file, 2, 2040 + shift, 2, 2045 + shift)
    assert b.visuals[0].span == Span(file, 2, 2055 + shift, 2, 2062 + shift)
    assert robot.joints["j"].span == Span(file, 2, 2119 + shift, 2, 2125 + shift)  # type: ignore[attr-defined]


def test_an_error_in_a_minified_urdf_names_the_attributes_line_and_column(tmp_path: Path) -> None:
    _, sink, file = _read(tmp_path, '<?xml version="1.0"?>\n' + BODY.format(type="bogus"))
    [error] = sink.diagnostics
    assert (error.code, error.message) == ("E0422", "joint 'j' has unknown type 'bogus'")
    assert error.span == Span(file, 2, 2141, 2, 2146)  # `<joint name="j" type="` is 22 long


def test_a_start_tag_that_begins_on_a_long_line_and_ends_on_the_next_is_located(tmp_path: Path) -> None:
    text = BODY.format(type="bogus").replace(' type="bogus">', '\n   type="bogus">')
    _, sink, file = _read(tmp_path, text)
    [error] = sink.diagnostics
    assert error.code == "E0422" and error.span == Span(file, 2, 10, 2, 15)


@pytest.mark.parametrize("end", ["\n", "\r\n", "\r"], ids=["LF", "CR LF", "CR"])
def test_an_error_is_located_at_its_line_whatever_ends_the_lines(tmp_path: Path, end: str) -> None:
    """libxml2 ends a line at CR LF, CR or LF (as XML says); so do spans and the quoted line."""
    lines = ['<robot name="r">', '  <link name="a"/>', '  <joint name="j" type="bogus">',
             '    <parent link="a"/><child link="b"/>', "  </joint>", '  <link name="b"/>', "</robot>"]
    robot, sink, file = _read(tmp_path, end.join(lines) + end)
    [error] = sink.diagnostics
    assert robot is None and error.code == "E0422"
    assert error.span == Span(file, 3, 25, 3, 30)  # `  <joint name="j" type="` is 24 long
    assert source_line(file, 3) == lines[2]
