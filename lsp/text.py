"""An editor's buffer → LSP positions and the YAML context at the cursor; no parsing beyond lines.

Spans (core/span.py) count lines and columns from 1 in code points; LSP counts from 0 in
UTF-16 code units. The cursor's context (the keys above it, whether a key or a value is
being written) is read from the indentation, because a buffer being typed is often no
valid YAML.
"""

from __future__ import annotations

import re

from mpc.core.record import record
from mpc.core.span import Span
from mpc.lsp.structures import Position, Range


def utf16_length(text: str) -> int:
    return sum(2 if ord(c) > 0xFFFF else 1 for c in text)


class Lines:
    """The lines of one text, converting between Span columns and LSP positions."""

    def __init__(self, text: str) -> None:
        self.lines = text.split("\n")

    def line(self, number: int) -> str:
        """Line `number` (0-based), or ''."""
        return self.lines[number] if 0 <= number < len(self.lines) else ""

    def position(self, line: int, col: int) -> Position:
        """The LSP position of a 1-based (line, column in code points)."""
        text = self.line(line - 1)
        return Position(line=max(line - 1, 0), character=utf16_length(text[:max(col - 1, 0)]))

    def column(self, position: Position) -> int:
        """The 1-based column in code points of an LSP position."""
        text, units, col = self.line(position["line"]), 0, 0
        while col < len(text) and units < position["character"]:
            units += 2 if ord(text[col]) > 0xFFFF else 1
            col += 1
        return col + 1

    def range(self, span: Span) -> Range:
        """The range of a span; a span without an end covers the word it starts at."""
        end_line, end_col = span.end_line, span.end_col
        if (end_line, end_col) == (span.line, span.col):
            text = self.line(span.line - 1)
            match = re.compile(r"[^\s,\]\}]*").match(text, span.col - 1)
            end_col = span.col + (len(match.group()) if match else 0)
            if end_col == span.col:
                end_col = len(text) + 1
        return Range(start=self.position(span.line, span.col), end=self.position(end_line, end_col))


def contains(span: Span, line: int, col: int) -> bool:
    """Whether 1-based (line, col) is inside the span (its end included: a cursor after a word)."""
    return (span.line, span.col) <= (line, col) <= (span.end_line, span.end_col)


@record
class Context:
    """What is written at the cursor.

    keys: the mapping keys above it, outermost first ("-" for a list item).
    key: the key of the cursor's line when a value is being written after it, else None.
    word: what is typed before the cursor (the start of a key, a name or a path).
    in_list: the value is an item of a flow list (`[a, b|`).
    """

    keys: tuple[str, ...]
    key: str | None
    word: str
    in_list: bool = False


_KEY = re.compile(r"^(\s*)(?:-\s+)?([^\s:#][^:#]*?)\s*:(?:\s|$)")


def context(lines: Lines, line: int, col: int) -> Context:
    """The context of 0-based `line` at 1-based `col` (code points)."""
    text = lines.line(line)[:col - 1]
    indent = len(text) - len(text.lstrip(" -"))
    keys: list[str] = []
    key: str | None = None
    word = re.search(r"[^\s:\[\],{}\"']*$", text).group()  # type: ignore[union-attr]
    in_list = False
    stripped = text.lstrip()
    item = stripped.startswith("- ")
    own = _KEY.match(text)
    if own and own.group(2).startswith(("{", "[")):
        own = None  # the line's value is a flow collection (`- {model: arm, joint: {…`): below
    inner: list[str] = []
    if own:
        key = own.group(2).strip("'\"")
        rest = text[own.end():]
        in_list = "[" in rest and "]" not in rest
        if item:
            keys.append("-")
        flow = _open_flow(rest)
        if flow is not None:  # `key: {a: …, b: |`: the cursor is inside a flow mapping
            inner, in_list = [key, *flow[0]], flow[2]
            key = flow[1]
    elif item:
        keys.append("-")
    if not own:
        flow = _open_flow(stripped[2:] if item else stripped)
        if flow is not None:
            inner, key, in_list = flow
    # the keys of the lines above with less indentation
    limit = len(text) - len(text.lstrip(" ")) if own or item else indent
    for number in range(line - 1, -1, -1):
        above = lines.line(number)
        if not above.strip() or above.lstrip().startswith("#"):
            continue
        spaces = len(above) - len(above.lstrip(" "))
        if spaces >= limit:
            continue
        match = _KEY.match(above)
        dash = above.lstrip().startswith("- ")
        key_indent = match.start(2) if match else spaces
        if match and key_indent < limit:
            keys.append(match.group(2).strip("'\""))
        if dash:
            keys.append("-")
        limit = spaces
        if spaces == 0:
            break
    keys.reverse()
    return Context((*keys, *inner), key, word, in_list)


def _open_flow(text: str) -> tuple[list[str], str | None, bool] | None:
    """Where the end of `text`, a value written after a key, is inside flow collections that
    are still open: the keys of the open mappings that lead there (outermost first), the key
    whose value is being written in the innermost mapping (None: a key is being written), and
    whether the innermost collection is a list. None when no flow collection is open.

        {parent: base, name: |     → ([], "name", False)
        {a: {b: [x, |              → (["a"], "b", True)
    """
    frames: list[list] = []  # [bracket, the key being written or None]
    token = ""
    quote = ""
    for at, char in enumerate(text):
        if quote:
            token += char
            quote = "" if char == quote else quote
        elif char in "'\"":
            quote, token = char, token + char
        elif char in "{[":
            frames.append([char, None])
            token = ""
        elif char in "}]":
            if frames:
                frames.pop()
            token = ""
        elif char == "," and frames:
            if frames[-1][0] == "{":
                frames[-1][1] = None
            token = ""
        elif char == ":" and frames and frames[-1][0] == "{" and text[at + 1:at + 2] in ("", " "):
            frames[-1][1] = token.strip().strip("'\"") or None
            token = ""
        else:
            token += char
    if not any(bracket == "{" for bracket, _ in frames):
        return None  # no mapping open (a flow list alone is the caller's `in_list`)
    path: list[str] = []
    for bracket, key in frames[:-1]:
        if bracket == "{" and key is not None:
            path.append(key)
    bracket, key = frames[-1]
    if bracket == "[":  # a list item: the key of the mapping the list is the value of
        return path[:-1] if path else path, path[-1] if path else None, True
    return path, key, False
