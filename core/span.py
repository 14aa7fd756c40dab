"""Span: where in which file something was written; 1-based line and column.

Every AST node, IR op and IR element read from a file carries one, so that an error
found at any stage points at the user's text.
"""

from __future__ import annotations

import os
import types
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any, Protocol, cast

from mpc.core.files import quotable
from mpc.core.record import lazy_twin, record, record_of, record_values


@record(slots=True, bulk=True)
class Span:
    """A region of a source file.

    file: the path as given (kept as the user wrote it, for messages).
    line, col: the first character, 1-based.
    end_line, end_col: one past the last character; equal to line/col when unknown.
    """

    file: str
    line: int = 1
    col: int = 1
    end_line: int = 0
    end_col: int = 0

    def __post_init__(self) -> None:
        if self.end_line < self.line or (self.end_line == self.line and self.end_col < self.col):
            object.__setattr__(self, "end_line", self.line)
            object.__setattr__(self, "end_col", self.col)

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"

    @classmethod
    def of_file(cls, file: str) -> Span:
        """The span of a whole file, for errors that concern the file itself."""
        return cls(file, 1, 1)


_POSITION = frozenset({"line", "col", "end_line", "end_col"})
_set_file, _set_line, _set_col, _set_end_line, _set_end_col = (
    Span.__dict__[name].__set__ for name in ("file", "line", "col", "end_line", "end_col"))


class Locator(Protocol):
    """What finds the span of a node of a parsed file (backends/xml.py: XmlSource)."""

    def span(self, node: Any, attr: str | None = None, /) -> Span: ...


@lazy_twin(Span)
class LazySpan(Span):
    """A Span whose position is found when it is first asked for (`lazy_span`, `located_span`).

    A reader knows where each element is but seldom needs to say so: only a diagnostic, the
    language server or a kept build (which writes it) asks. Finding the column of a start
    tag or an attribute is most of what a span costs (about 8% of TALOS's URDF read, 330
    spans). Until then it holds the finder, and with it the parsed file; afterwards it is a
    Span in all but its class, and it pickles and copies as one.

    _find is a function of no arguments, or (when `_node` is not None) a Locator asked for
    the span of `_node` (and of its attribute `_attr`): a reader's spans hold their element
    and the parsed file themselves, not a partial and a bound method each (three objects
    fewer per span to make, free and scan for garbage cycles; a URDF read makes hundreds).
    """

    __slots__ = ("_attr", "_find", "_node")
    _find: Callable[[], Span] | Locator | None
    _node: Any
    _attr: str | None

    def __getattr__(self, name: str) -> Any:  # only for a slot not set yet: the position
        find = object.__getattribute__(self, "_find") if name in _POSITION else None
        if find is None:
            raise AttributeError(name)
        node = object.__getattribute__(self, "_node")
        found = find() if node is None else find.span(node, object.__getattribute__(self, "_attr"))
        _set_line(self, found.line)
        _set_col(self, found.col)
        _set_end_line(self, found.end_line)
        _set_end_col(self, found.end_col)
        _set_find(self, None)  # lets the parsed file go
        _set_node(self, None)
        return object.__getattribute__(self, name)


_set_find, _set_node, _set_attr = (LazySpan.__dict__[name].__set__ for name in ("_find", "_node", "_attr"))
_new = object.__new__


def lazy_span(file: str, find: Callable[[], Span]) -> Span:
    """A Span of `file` whose position `find` gives when first asked for (LazySpan)."""
    span = _new(LazySpan)
    _set_file(span, file)
    _set_find(span, find)
    _set_node(span, None)
    return span


def located_span(file: str, locator: Locator, node: Any, attr: str | None = None) -> Span:
    """A Span of `file` that `locator.span(node, attr)` gives when first asked for (LazySpan);
    `node` is not None."""
    span = _new(LazySpan)
    _set_file(span, file)
    _set_find(span, locator)
    _set_node(span, node)
    _set_attr(span, attr)
    return span


_PLAIN = (str, int, float, bool, bytes, type(None))


def settle_spans(value: object) -> int:
    """Find the position of every lazy span in `value` (records, tuples, lists, sets and dicts,
    however nested) and let go of its finder: what enters a long-lived cache must not keep the
    parsed file its spans were read from alive (40 TALOS models held: 76 MiB with their parses,
    14 MiB without). The number of spans found."""
    found, seen, stack = 0, set(), [value]
    while stack:
        item = stack.pop()
        kind = type(item)
        if kind is LazySpan:
            if object.__getattribute__(item, "_find") is not None:
                cast(LazySpan, item).line  # noqa: B018  (asking for it finds it)
                found += 1
            continue
        if kind in _PLAIN or kind is Span or id(item) in seen:
            continue
        seen.add(id(item))
        if kind is dict or kind is types.MappingProxyType:
            stack.extend(item.keys())  # type: ignore[attr-defined]
            stack.extend(item.values())  # type: ignore[attr-defined]
        elif kind in (tuple, list, set, frozenset):
            stack.extend(item)  # type: ignore[call-overload]
        elif record_of(kind) is not None:  # asking a lazy twin (a fragment) for its values finds them
            stack.extend(record_values(item))
    return found


def hardened_parser(huge: bool = False) -> Any:
    """The one lxml parser of mpc (here, on the ground floor, for readers and IR alike): no
    DTD, no entity expansion, no network; huge trees only when asked (meshes: DAE files
    hold long arrays). A new parser per call: lxml parsers must not be shared between threads."""
    from lxml import etree

    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=huge,
                           remove_blank_text=False)


def source_line(file: str, line: int) -> str | None:
    """Line `line` (1-based) of `file` as it is now, or None; for diagnostics and columns.

    Files are read once per (modification time, size), so an edited file is read again.
    """
    if not quotable(file):  # the read rule's (core/files.py): no line of /proc/self/environ
        return None
    try:
        stat = os.stat(file)
        lines = _source_lines(file, (stat.st_mtime_ns, stat.st_size))
    except (OSError, UnicodeDecodeError):
        return None
    return lines[line - 1] if 0 < line <= len(lines) else None


@lru_cache(maxsize=16)
def _source_lines(file: str, stamp: tuple[int, int]) -> tuple[str, ...]:
    return tuple(Path(file).read_text(encoding="utf-8").split("\n"))
