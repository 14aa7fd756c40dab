"""The editor's open buffers: their text and version as didOpen and didChange give them.

The server syncs incrementally (a change may replace a range of the text); ranges count lines
from 0 and characters in UTF-16 code units, as LSP does, with `\\n`, `\\r\\n` and `\\r` as line
breaks. A position past the end of its line means the line's end, one past the last line the
text's end (LSP 3.17, Position).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from urllib.parse import unquote, urlsplit

from mpc.core.record import record
from mpc.lsp.structures import Position, Range

_BREAK = re.compile(r"\r\n|\r|\n")


@record(frozen=False)
class Document:
    uri: str
    text: str
    version: int | None


def path_of(uri: str) -> Path:
    """The file a `file:` URI names (percent-escapes decoded); another URI as it is."""
    parts = urlsplit(uri)
    if parts.scheme != "file":
        return Path(uri)
    path = unquote(parts.path)
    return Path(f"//{parts.netloc}{path}" if parts.netloc not in ("", "localhost") else path)


def offset(text: str, at: Position) -> int:
    """The index in `text` of an LSP position."""
    start = 0
    for _ in range(at["line"]):
        found = _BREAK.search(text, start)
        if found is None:
            return len(text)
        start = found.end()
    found = _BREAK.search(text, start)
    end = found.start() if found else len(text)
    index, units = start, 0
    while index < end and units < at["character"]:
        units += 2 if ord(text[index]) > 0xFFFF else 1
        index += 1
    return index


def replaced(text: str, where: Range, new: str) -> str:
    """`text` with the range `where` replaced by `new`."""
    start, end = offset(text, where["start"]), offset(text, where["end"])
    return text[:start] + new + text[max(start, end):]


class Documents:
    """The open buffers by URI."""

    def __init__(self) -> None:
        self.open: dict[str, Document] = {}

    def opened(self, uri: str, text: str, version: int) -> None:
        self.open[uri] = Document(uri, text, version)

    def changed(self, uri: str, version: int, changes: list[dict]) -> bool:
        """Apply didChange's changes in order; False when the buffer is not open."""
        document = self.open.get(uri)
        if document is None:
            return False
        for change in changes:
            where, new = change.get("range"), change["text"]
            document.text = new if where is None else replaced(document.text, where, new)
        document.version = version
        return True

    def closed(self, uri: str) -> None:
        self.open.pop(uri, None)

    def texts(self) -> dict[str, str]:
        """The text of each open buffer by its file's absolute path (what the check overlays)."""
        return {os.path.abspath(path_of(uri)): doc.text for uri, doc in self.open.items()}
