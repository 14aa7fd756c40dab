"""A frozen copy of backends/xml.py's XmlSource (and load) as it was before the URDF reader
became faster (issue 19): tests/backends/test_reader_differential.py compares the spans of the
new XmlSource and what the new reader reads against it. A test fixture, never imported by mpc.

The original docstring: safe XML parsing with located elements.

Parsing: no entity expansion, no network, no DTD. lxml knows only the line of an
element (where its start tag ends); `XmlSource` finds where each start tag and
attribute really begins, so that diagnostics carry a line *and* a column.
"""

from __future__ import annotations

import bisect
import functools
import itertools
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from mpc.core.diagnostics import Sink
from mpc.core.span import Span, hardened_parser

# Comments, CDATA, processing instructions, doctype and start tags (`<` and the name), in
# document order: the start tags among them are those outside the others.
_TOKENS = re.compile(
    r"(<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<!DOCTYPE[^>]*>|<[A-Za-z_][\w:.\-]*)", re.DOTALL
)


class XmlError(Exception):
    """The text is not well-formed XML; carries the position libxml2 reported."""

    def __init__(self, message: str, line: int, col: int) -> None:
        super().__init__(message)
        self.message, self.line, self.col = message, line, col


@dataclass
class XmlSource:
    """A parsed XML file that can say where each of its elements and attributes is."""

    file: str
    text: str
    root: etree._Element
    _line_starts: list[int] = field(default_factory=list)
    _offsets: dict[etree._Element, int] = field(default_factory=dict)

    @classmethod
    def parse(cls, data: bytes, file: str) -> XmlSource:
        """Parse `data`; raises XmlError when it is not well-formed."""
        try:
            root = etree.fromstring(data, hardened_parser())
        except etree.XMLSyntaxError as e:
            line, col = e.position if e.position else (1, 1)
            # libxml2 appends ", line N, column M"; the span carries the position.
            message = re.sub(r", line \d+, column \d+$", "", str(e.msg).strip())
            raise XmlError(message, max(line, 1), max(col, 1)) from None
        # Entities stay unexpanded (no DTD is read): one kept in a fragment would make the
        # output not well-formed, so a file that uses any is refused here.
        for entity in root.iter(etree.Entity):
            raise XmlError(f"entity reference '{entity.text}' (mpc expands no entities; write "
                           "the text itself)", entity.sourceline or 1, 1)
        text = data.decode("utf-8", errors="replace")
        src = cls(file, text, root)
        src._line_starts = [0] + [m.end() for m in re.finditer("\n", text)]
        # split, not finditer: the offsets come from the parts' lengths without a match object
        # per token (twice as fast on a large URDF); parts alternate text and token.
        parts = _TOKENS.split(text)
        offsets = itertools.accumulate(map(len, parts), initial=0)
        starts = [(offset, token[1:]) for offset, token in zip(
            itertools.islice(offsets, 1, None, 2), parts[1::2], strict=False) if token[1] not in "!?"]
        elements = list(root.iter(etree.Element))
        if len(starts) != len(elements):
            return src
        tags = [tag for _, tag in starts]
        if tags == [el.tag for el in elements] and ":" not in "".join(tags):  # no namespaces
            src._offsets = dict(zip(elements, (offset for offset, _ in starts), strict=True))
            return src
        for el, (offset, tag) in zip(elements, starts, strict=True):
            if tag.rsplit(":", 1)[-1] == _localname(el):
                src._offsets[el] = offset
        return src

    def _pos(self, offset: int) -> tuple[int, int]:
        line = bisect.bisect_right(self._line_starts, offset)
        return line, offset - self._line_starts[line - 1] + 1

    def span(self, el: etree._Element, attr: str | None = None) -> Span:
        """The span of an element's start tag, or of one of its attribute values."""
        offset = self._offsets.get(el)
        if offset is None:
            line = el.sourceline or 1
            return Span(self.file, line, 1)
        if attr is not None:
            end = self.text.find(">", offset)
            m = _attribute_pattern(attr).search(self.text, offset, end + 1 if end >= 0 else len(self.text))
            if m:
                line, col = self._pos(m.start(2))
                end_line, end_col = self._pos(m.end(2))
                return Span(self.file, line, col, end_line, end_col)
        line, col = self._pos(offset)
        return Span(self.file, line, col, line, col + 1 + len(_localname(el)))  # "<" and the name


@functools.lru_cache(maxsize=256)
def _attribute_pattern(attr: str) -> re.Pattern[str]:
    """Where the value of attribute `attr` is in a start tag (group 2)."""
    return re.compile(rf"\s{re.escape(attr)}\s*=\s*([\"'])(.*?)\1", re.DOTALL)


def _localname(el: etree._Element) -> str:
    """etree.QName(el).localname, without building a QName (`{namespace}name` → `name`)."""
    return str(el.tag).rpartition("}")[2]


def load(path: Path, sink: Sink, kind: str, file: str | None = None) -> XmlSource | None:
    """Read and parse the `kind` file (URDF, SDF) at `path`; None after a located diagnostic."""
    file = file or str(path)
    try:
        data = path.read_bytes()
    except OSError as e:
        sink.error(Span.of_file(file), "E0601", f"cannot read {kind} '{file}': {e.strerror}")
        return None
    try:
        return XmlSource.parse(data, file)
    except XmlError as e:
        sink.error(Span(file, e.line, e.col), "E0401", f"malformed XML in '{file}': {e.message}")
        return None


def parse_floats(text: str | None) -> tuple[float, ...] | None:
    """Whitespace-separated numbers, or None when any token is not a number."""
    if text is None or "_" in text:  # float() would accept "1_0"; URDF does not
        return None
    try:
        return tuple(map(float, text.split()))
    except ValueError:
        return None
