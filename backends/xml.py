"""Safe XML parsing with located elements, and canonical number formatting.

Parsing: no entity expansion, no network, no DTD. lxml knows only the line of an
element (where its start tag ends); `XmlSource` finds where each start tag and
attribute really begins, so that diagnostics carry a line *and* a column.
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
import re
from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from lxml import etree

from mpc.core.diagnostics import Sink
from mpc.core.record import maker, record
from mpc.core.span import Span, hardened_parser, located_span

# Comments, CDATA, processing instructions, doctype and start tags (`<` and the name), in
# document order: the start tags among them are those outside the others.
_TOKENS = re.compile(
    r"(<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<!DOCTYPE[^>]*>|<[A-Za-z_][\w:.\-]*)", re.DOTALL
)
# A `<` that _TOKENS would not see as markup or as a start tag with its whole name (the name
# starts with a non-ASCII letter or holds a character outside \w:.-): only in a non-ASCII text.
_ODD_START = re.compile(r"<(?![!?/]|[A-Za-z_][\w:.\-]*[ \t\r\n/>])")
# Encodings in which the text, decoded as UTF-8, has every `<` and ASCII name where libxml2 saw it.
_PLAIN_ENCODINGS = frozenset({"utf-8", "utf8", "us-ascii", "ascii", "iso-8859-1", "latin1", "latin-1"})
_DELIMITERS = frozenset(" \t\r\n/>")  # what may follow an element's name in its start tag
_LOOK_BACK = 50  # lines above an element's last line that may hold the `<` of its start tag
# A line longer than this (a minified file: the whole text on one line) is not searched for each
# element, which would take time in the square of its length: the scan finds every start tag once.
_LONG_LINE = 2000


class XmlError(Exception):
    """The text is not well-formed XML; carries the position libxml2 reported."""

    def __init__(self, message: str, line: int, col: int) -> None:
        super().__init__(message)
        self.message, self.line, self.col = message, line, col


@record(frozen=False)
class XmlSource:
    """A parsed XML file that can say where each of its elements and attributes is.

    An element's start tag is looked for on the line where lxml says it ends: when that line
    holds it beyond doubt (see `_on_line`), nothing else is read. Otherwise, and for every
    element of an unusual text (a DOCTYPE, odd names or encodings), the start tags of the
    whole text are scanned once (`_scan`) and the elements matched to them in order.
    """

    file: str
    text: str
    root: etree._Element
    _lines: list[str] | None = None  # the text's lines, split when a span first needs them
    _quick: bool = False  # whether `_on_line` may be asked (see `parse`)
    _offsets: dict[etree._Element, int] | None = None  # the scan: start tag offsets, once made
    _line_starts: list[int] = field(default_factory=list)
    # Span's maker (core/record.py): a file's spans are made here, one for nearly every element.
    _new_span: Callable[..., Span] = Span

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
        # output not well-formed, so a file that uses any is refused here. Only a file with a
        # DOCTYPE may hold one: without, libxml2 refuses every entity it does not define.
        info = root.getroottree().docinfo
        if info.doctype:
            for entity in root.iter(etree.Entity):
                raise XmlError(f"entity reference '{entity.text}' (mpc expands no entities; write "
                               "the text itself)", entity.sourceline or 1, 1)
        text = data.decode("utf-8", errors="replace")
        if "\r" in text:  # a line ends at CR LF, CR or LF, as libxml2 counts lines (and Python reads text)
            text = text.replace("\r\n", "\n").replace("\r", "\n")
        src = cls(file, text, root, _new_span=maker(Span))
        # The scan matches every element to its own start tag, and `_on_lines` may look for it,
        # when the text has no DOCTYPE (its internal subset may hold a `<name` that is no tag;
        # elsewhere the scan skips it with the comment, CDATA or PI that holds it), no name the
        # scan does not see whole (`<:x`, when libxml2 takes it; odd letters), an encoding that
        # writes each `<` of the markup as `<` (not UTF-7's `+ADw-`), and lines that libxml2
        # counts for each element (past 65535 only with XML_PARSE_BIG_LINES; the last node's
        # line is the largest, and asked for in less time than the text's lines are counted).
        src._quick = (not info.doctype and _last_line(root) < 65535
                      and (info.encoding or "").lower() in _PLAIN_ENCODINGS
                      and (text.isascii() or _ODD_START.search(text) is None)
                      and (not _colon_names() or "<:" not in text))
        return src

    def span(self, el: etree._Element, attr: str | None = None) -> Span:
        """The span of an element's start tag, or of one of its attribute values."""
        where = self._on_lines(el) if self._quick else None
        if where is None:
            where = self._scanned(el)
            if where is None:
                return self._new_span(self.file, el.sourceline or 1, 1)
        number, chunk, start, name, base = where
        if attr is not None:
            end = chunk.find(">", start)
            m = _attribute_pattern(attr).search(chunk, start, end + 1 if end >= 0 else len(chunk))
            if m:
                line, col = _position(chunk, number, m.start(m.lastindex), base)  # type: ignore[arg-type]
                end_line, end_col = _position(chunk, number, m.end(m.lastindex), base)  # type: ignore[arg-type]
                return self._new_span(self.file, line, col, end_line, end_col)
        col = base + start + 1
        return self._new_span(self.file, number, col, number, col + 1 + name)  # "<" and the name

    def lazy_span(self, el: etree._Element, attr: str | None = None) -> Span:
        """`span(el, attr)`, found when first asked for (core/span.py: LazySpan): for the
        spans of what a reader makes, which only a diagnostic or the language server reads."""
        return located_span(self.file, self, el, attr)

    def _on_lines(self, el: etree._Element) -> tuple[int, str, int, int, int] | None:
        """Where `el`'s start tag begins, read from the line where it ends (lxml's sourceline)
        and the lines above: (the number of the line it begins on, the text from there to the
        line where it ends, the index of its `<` in that text, the length of its local name, 0:
        the text begins its line), or None when they do not tell (or a line is too long to ask).

        Why the lines tell: a tag that begins on an earlier line leaves on its last line only
        the end of its attributes (which hold no `<`) and its `>`, before any `<`, and began
        at the last `<` above that line. A tag that begins on its last line is one of the
        `<name` there. So when that line has one `<name` and either no `>` before its first
        `<` or no `<name` as the last `<` above it, the tag begins at that `<name`; when it has
        none, at the last `<` above.
        """
        number, lines = el.sourceline, self._lines or self._split()
        if not number or number > len(lines) or len(lines[number - 1]) > _LONG_LINE:
            return None
        line, tag = lines[number - 1], el.tag
        if tag[0] == "{":
            local = tag.rpartition("}")[2]
            written = f"{el.prefix}:{local}" if el.prefix else local
        elif ":" in tag:  # a QName libxml2 2.12 refuses and older ones keep whole: the scan decides
            return None
        else:
            local = written = tag
        needle = "<" + written
        start = line.find(needle)
        if start >= 0 and line.find(needle, start + 1) < 0:  # most tags: alone on one line
            end = start + len(needle)
            if (end == len(line) or line[end] in _DELIMITERS) and line.find(">", 0, line.find("<")) < 0:
                return number, line, start, len(local), 0
        here = _starts(line, needle)
        if len(here) == 1 and line.find(">", 0, line.find("<")) < 0:
            where = number, line, here[0]
        elif len(here) > 1:
            return None
        else:
            above = self._above(number)
            if above is None:
                return None
            first, start = above
            chunk = "\n".join(lines[first - 1:number])
            begins = bool(_starts(chunk[start:start + len(needle) + 1], needle))
            if here and not begins:
                where = number, line, here[0]
            elif begins and not here:
                where = first, chunk, start
            else:
                return None
        return (*where, len(local), 0)

    def _split(self) -> list[str]:
        """The text's lines: split when the first span is asked for (a read that reports
        nothing may find none: its spans are lazy)."""
        self._lines = self.text.split("\n")
        return self._lines

    def _above(self, number: int) -> tuple[int, int] | None:
        """(line number, index) of the last `<` above line `number`, when one of the few lines
        right above it has one."""
        lines = self._lines or self._split()
        for k in range(number - 2, max(number - 2 - _LOOK_BACK, -1), -1):
            if len(lines[k]) > _LONG_LINE:
                return None
            i = lines[k].rfind("<")
            if i >= 0:
                return k + 1, i
        return None

    def _scanned(self, el: etree._Element) -> tuple[int, str, int, int, int] | None:
        """Where the scan found `el`'s start tag (as `_on_lines` says it, the text beginning at
        the tag: its column less one last), or None."""
        if self._offsets is None:
            self._scan()
        offset = self._offsets.get(el)  # type: ignore[union-attr]
        if offset is None:
            return None
        number = bisect.bisect_right(self._line_starts, offset)
        line_start = self._line_starts[number - 1]
        end = self.text.find(">", offset)
        return (number, self.text[offset:end + 1 if end >= 0 else len(self.text)], 0, len(_localname(el)),
                offset - line_start)

    def _scan(self) -> None:
        """The offset of every element's start tag, from one pass over the whole text."""
        text, root = self.text, self.root
        self._offsets = {}
        self._line_starts = [0] + [m.end() for m in re.finditer("\n", text)]
        # split, not finditer: the offsets come from the parts' lengths without a match object
        # per token (twice as fast on a large URDF); parts alternate text and token.
        parts = _TOKENS.split(text)
        offsets = itertools.accumulate(map(len, parts), initial=0)
        starts = [(offset, token[1:]) for offset, token in zip(
            itertools.islice(offsets, 1, None, 2), parts[1::2], strict=False) if token[1] not in "!?"]
        elements = list(root.iter(etree.Element))
        if len(starts) != len(elements):
            return
        tags = [tag for _, tag in starts]
        if tags == [el.tag for el in elements] and ":" not in "".join(tags):  # no namespaces
            self._offsets = dict(zip(elements, (offset for offset, _ in starts), strict=True))
            return
        for el, (offset, tag) in zip(elements, starts, strict=True):
            if tag.rsplit(":", 1)[-1] == _localname(el):
                self._offsets[el] = offset


def _last_line(root: etree._Element) -> int:
    """The line lxml gives the last node inside `root` (0 when it gives none)."""
    node = root
    while len(node):
        node = node[-1]
    return node.sourceline or 0


@functools.cache
def _colon_names() -> bool:
    """Whether this libxml2 takes an element name that begins with `:` (2.12 refuses it, so
    the text need not be searched for one)."""
    try:
        etree.fromstring(b"<a><:b/></a>", hardened_parser())
    except etree.XMLSyntaxError:
        return False
    return True


@functools.lru_cache(maxsize=256)
def _attribute_pattern(attr: str) -> re.Pattern[str]:
    """Where the value of attribute `attr` is in a start tag (the group that matched: 1 in double
    quotes, 2 in single ones; a class of characters, not `(.*?)` and a back-reference, which
    tried the closing quote at every character)."""
    return re.compile(rf"\s{re.escape(attr)}\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


def _starts(text: str, needle: str) -> list[int]:
    """Where `needle` (`<` and a name) occurs in `text` followed by what may end a name."""
    out, i = [], text.find(needle)
    while i >= 0:
        end = i + len(needle)
        if end == len(text) or text[end] in _DELIMITERS:
            out.append(i)
        i = text.find(needle, i + 1)
    return out


def _position(chunk: str, number: int, index: int, base: int) -> tuple[int, int]:
    """The line and column of `chunk[index]`, `chunk` beginning on line `number` after `base`
    characters of it."""
    newline = chunk.rfind("\n", 0, index)
    return number + chunk.count("\n", 0, index), index - newline if newline >= 0 else base + index + 1


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


def fmt_float(x: float) -> str:
    """The shortest text that reads back as exactly `x`; integers without '.0'."""
    if x == 0.0:
        return "0"
    if x.__class__ is float:  # repr writes an integer below 1e16 with '.0', larger ones with 'e'
        text = repr(x)
        return text[:-2] if text.endswith(".0") else text
    if math.isfinite(x) and x.is_integer() and abs(x) < 1e16:
        return str(int(x))
    return repr(x)


def fmt_floats(xs: tuple[float, ...] | list[float]) -> str:
    return " ".join(fmt_float(x) for x in xs)


def parse_floats(text: str | None) -> tuple[float, ...] | None:
    """Whitespace-separated numbers, or None when any token is not a number."""
    if text is None or "_" in text:  # float() would accept "1_0"; URDF does not
        return None
    if " " not in text:  # most often one number: float() strips the whitespace split() would
        try:
            return (float(text),)
        except ValueError:
            pass  # not one number; maybe several, between tabs or newlines
    try:
        return tuple(map(float, text.split()))
    except ValueError:
        return None


NOT_FINITE = (math.nan,)  # finite_floats: numbers, one of them nan or ±inf


def finite_floats(text: str | None) -> tuple[float, ...] | None:
    """parse_floats(text), or NOT_FINITE when a number is nan or ±inf: URDF's and SDFormat's
    readers refuse them, so an input holding one is refused where it is read (E0480)."""
    values = parse_floats(text)
    if values is not None and not all(map(math.isfinite, values)):
        return NOT_FINITE
    return values


def write_path(path: Path, data: str) -> None:
    """Write a text output file (core/files.py: all or nothing)."""
    from mpc.core.files import write_atomic

    write_atomic(path, data)
