"""Where each link and joint of a xacro model is written: its file (the xacro file or one it
includes, a macro's file for an element a macro makes) and line. For the language server's go
to definition and hover (lsp/lookup.py): a xacro model is read from the URDF xacro expands it
to (xacro_reader.py), which is in no file, so its elements' spans are lines of that expansion.

The model is expanded once more by xacro_reader.expand, under the same rules, while every
`<link>` and `<joint>` element that xacro parses gets an attribute `mpc-origin` that numbers
the (file, line, column) its parser was at. xacro copies attributes wherever it copies an
element (a macro's body, an include), so each element of the expansion still carries where it
was written, however its name was put together. The attribute is only in this second
expansion, never in the model mpc reads.

While it runs, `xml.dom.minidom.parse` and `parseString` (what xacro parses with) record
lines: one expansion at a time, in the thread that asks (the language server's only one).
"""

from __future__ import annotations

import contextlib
import xml.dom.minidom
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from xml.dom import expatbuilder

from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.core.span import Span

ORIGIN = "mpc-origin"
_KINDS = ("link", "joint")


def origins(path: Path, resolver: PackageResolver,
            args: tuple[tuple[str, str], ...] = ()) -> dict[int, tuple[str, Span]]:
    """The links and joints of the robot the xacro at `path` expands to with `args`, by their
    line in the expansion (the line of their span in the model mpc reads: the attribute adds
    no line): their kind and where they are written. Empty when the model does not expand."""
    from lxml import etree

    from mpc.backends import xacro_reader

    places: list[tuple[str, int, int]] = []
    with _recording(places):
        text = xacro_reader.expand(path, Sink(), resolver, args)
    if text is None:
        return {}
    try:
        root = etree.fromstring(text.encode())
    except etree.XMLSyntaxError:
        return {}
    out: dict[int, tuple[str, Span]] = {}
    for element in root:
        number = element.get(ORIGIN)
        if element.tag in _KINDS and number is not None and number.isdigit() and int(number) < len(places):
            file, line, col = places[int(number)]
            end = col + 1 + len(element.tag)  # the tag's `<` and name
            out[element.sourceline] = (str(element.tag), Span(file, line, col, line, end))
    return out


@contextlib.contextmanager
def _recording(places: list[tuple[str, int, int]]) -> Iterator[None]:
    """xacro's parses number their links and joints' places into `places`."""
    import xacro

    class Builder(expatbuilder.ExpatBuilderNS):
        def start_element_handler(self, name: str, attributes: Any) -> None:
            super().start_element_handler(name, attributes)
            node = self.curNode
            stack = getattr(xacro, "filestack", None) or []
            if node.localName in _KINDS and stack and stack[-1]:
                parser = self._parser
                places.append((str(Path(stack[-1]).resolve()), parser.CurrentLineNumber,
                               parser.CurrentColumnNumber + 1))
                node.setAttribute(ORIGIN, str(len(places) - 1))

    def parse(file: Any, parser: Any = None, bufsize: Any = None) -> Any:
        if parser is not None or bufsize:
            return original_parse(file, parser, bufsize)
        builder = Builder()
        if isinstance(file, str):
            with open(file, "rb") as stream:
                return builder.parseFile(stream)
        return builder.parseFile(file)

    def parse_string(text: Any, parser: Any = None) -> Any:
        if parser is not None:
            return original_string(text, parser)
        return Builder().parseString(text)

    original_parse, original_string = xml.dom.minidom.parse, xml.dom.minidom.parseString
    xml.dom.minidom.parse, xml.dom.minidom.parseString = parse, parse_string
    try:
        yield
    finally:
        xml.dom.minidom.parse, xml.dom.minidom.parseString = original_parse, original_string
