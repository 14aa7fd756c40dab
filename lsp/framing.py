"""The base protocol of LSP on a byte stream: `Content-Length: N` header blocks, each followed
by N bytes of body. This reader replaced pygls 1.x's (`pygls.server.aio_readline` and
`JsonRPCProtocol.data_received`; the server no longer uses pygls at all, lsp/endpoint.py), which
lost its place for good after one bad frame: it passed
on only bodies that start with `{`, so after a `null` body it kept waiting for the rest of a
message that never came; a header without a usable Content-Length (missing, `abc`, `-2`) made
it gather every following line into one endless header; a huge length made it wait for bytes
no client will send.

Here every frame ends, well-formed or not, and the next one is found:

- A header line that is not `Name: value` is skipped. A `Content-Length:` found inside a line
  starts a new header there (what came before it was the tail of a damaged frame).
- A header without one valid Content-Length (missing, not a decimal number, given twice with
  different values, over `MAX_BODY`) cannot say where its body ends: the stream is read on to
  the next `Content-Length:` header, and the frame is refused.
- A body is read up to its length, unless a `Content-Length: N` line appears inside it first:
  no valid JSON text can hold one (JSON has no bare words, and its strings hold no raw line
  breaks), so that is the next frame, and the declared length was too large.
- A Content-Type whose charset is not UTF-8 (the only one LSP allows) refuses its frame.
- A header line longer than MAX_LINE is no header line: the stream is read on to the next
  header (a line is read in pieces of MAX_LINE bytes, each kept with the end of the one before,
  so that a header that a piece's end cuts is still found).

A refused frame comes out as a `Frame` with `problem` set, so that the server can say so.
"""

from __future__ import annotations

import re
from typing import BinaryIO

from mpc.core.record import record

MAX_BODY = 256 * 2**20  # bytes: larger is taken for a damaged header, not read
MAX_LINE = 8192  # bytes of a header line read at once
CHUNK = 65536
_KEEP = 64  # bytes of a line read in pieces kept with the next piece: a header line's start

# The start of a Content-Length header, anywhere in a line.
_LENGTH_START = re.compile(rb"content-length[ \t]*:", re.IGNORECASE)
# A whole Content-Length line inside a body: the next frame's header.
_LENGTH_LINE = re.compile(rb"content-length[ \t]*:[ \t]*\d+[ \t]*\r?\n", re.IGNORECASE)
_HEADER = re.compile(rb"([!-9;-~]+)[ \t]*:[ \t]*(.*?)[ \t]*\r?\n", re.DOTALL)
_UTF8 = {"utf-8", "utf8"}


@record
class Frame:
    """One frame of the stream: its body, or why it was refused (and the body is None)."""

    body: bytes | None
    problem: str | None = None


class FrameReader:
    """Frames from a blocking binary stream, one per `next()` call, None at its end."""

    def __init__(self, stream: BinaryIO) -> None:
        self.stream = stream
        self.pending = b""  # bytes read ahead: the start of the next header, found in a body

    def next(self) -> Frame | None:
        problem: str | None = None
        fields = False
        lengths: list[bytes] = []
        charset: str | None = None
        while True:
            line = self._line()
            if not line:
                return None
            if not line.endswith(b"\n"):  # longer than MAX_LINE: no header line is
                self.pending = line[-_KEEP:]
                self._skip_to_header()
                return Frame(None, f"a header line longer than {MAX_LINE} bytes; the stream was "
                                   "read on to the next header")
            found = _last_length_start(line)
            if found > 0:  # the tail of a damaged frame, then a new header
                line = line[found:]
                if fields:
                    problem = problem or "a header broken off by another Content-Length"
                fields, lengths, charset = False, [], None
            if line in (b"\r\n", b"\n"):
                if fields or problem:
                    break
                continue  # blank lines between frames
            header = _HEADER.fullmatch(line)
            if header is None:  # a damaged line: the rest of the header may still be good
                problem = problem or "a damaged header line"
                continue
            fields = True
            name, value = header.group(1).lower(), header.group(2)
            if name == b"content-length":
                lengths.append(value)
            elif name == b"content-type":
                charset = _charset(value) or charset
        length = _length(lengths)
        if isinstance(length, str):
            self._skip_to_header()
            return Frame(None, f"{length}; the stream was read on to the next header")
        body, short = self._body(length)
        if body is None:
            return None
        if short:
            return Frame(None, f"the body ended after {len(body)} of the {length} bytes its "
                               f"Content-Length gives, where the next header starts")
        if charset is not None and charset.lower() not in _UTF8:
            return Frame(None, f"the body's charset is {charset!r}; LSP messages are UTF-8")
        return Frame(body, problem)

    def _line(self) -> bytes:
        """The next line (with its line break), or at most MAX_LINE bytes of it; b"" at the end."""
        if self.pending:
            end = self.pending.find(b"\n")
            if end >= 0:
                line, self.pending = self.pending[:end + 1], self.pending[end + 1:]
                return line
            line = self.pending + self.stream.readline(MAX_LINE)
            self.pending = b""
            return line
        return self.stream.readline(MAX_LINE)

    def _skip_to_header(self) -> None:
        """Read on to the next `Content-Length:`, which is left to be read; a piece of a long line
        keeps its last bytes, so that a header cut by the piece's end is still found."""
        while True:
            line = self._line()
            if not line:
                return
            if not line.endswith(b"\n"):
                self.pending = line[-_KEEP:] if len(line) > _KEEP else b""
                continue
            found = _last_length_start(line)
            if found >= 0:
                self.pending = line[found:] + self.pending
                return

    def _body(self, length: int) -> tuple[bytes | None, bool]:
        """Up to `length` bytes, and whether a header inside cut them short (it is kept to be
        read next); None when the stream ends first."""
        body = bytearray(self.pending[:length])
        self.pending = self.pending[length:]
        searched = 0
        while True:
            found = _LENGTH_LINE.search(body, max(searched - 64, 0))
            if found:
                self.pending = bytes(body[found.start():]) + self.pending
                return bytes(body[:found.start()]), True
            searched = len(body)
            if len(body) >= length:
                return bytes(body), False
            chunk = self.stream.read1(min(length - len(body), CHUNK))  # type: ignore[attr-defined]
            if not chunk:
                return None, False
            body += chunk


def _last_length_start(line: bytes) -> int:
    """Where the last `Content-Length:` of a line starts, or -1. The last: a skipped body may
    quote the words in a string, but the header that follows it ends its line."""
    found = -1
    for match in _LENGTH_START.finditer(line):
        found = match.start()
    return found


def _length(values: list[bytes]) -> int | str:
    """The body's length from the Content-Length values of a header, or why there is none."""
    if not values:
        return "a header without Content-Length"
    if len(set(values)) > 1:
        return "a header with two different Content-Lengths"
    value = values[0]
    if not re.fullmatch(rb"\d+", value):
        return f"Content-Length {value.decode('latin-1')!r} is not a number of bytes"
    if int(value) > MAX_BODY:
        return f"Content-Length {int(value)} is over the {MAX_BODY} bytes a message may have"
    return int(value)


def _charset(value: bytes) -> str | None:
    """The charset parameter of a Content-Type value, if it has one."""
    for parameter in value.split(b";")[1:]:
        name, _, given = parameter.partition(b"=")
        if name.strip().lower() == b"charset":
            return given.strip().strip(b'"').decode("latin-1")
    return None
