"""The server's byte streams: frames read from stdin on a thread of their own, frames written to
stdout; and stdout kept for the protocol alone.

Reading on a thread lets the server wait for "the next frame, or the end of a debounce time,
whichever comes first" with a queue, and see what the client sent meanwhile (a cancellation)
while it is busy. Only the server's own thread parses and writes.
"""

from __future__ import annotations

import os
import queue
import sys
import threading
from typing import BinaryIO

from mpc.lsp import log
from mpc.lsp.framing import Frame, FrameReader

_END = None  # queued when the stream has ended


class Inbox:
    """The frames of a stream, read ahead by a daemon thread."""

    def __init__(self, stream: BinaryIO) -> None:
        self.frames: queue.SimpleQueue[Frame | None] = queue.SimpleQueue()
        self.ended = False
        threading.Thread(target=self._read, args=(FrameReader(stream),), name="lsp-reader",
                         daemon=True).start()

    def _read(self, reader: FrameReader) -> None:
        try:
            while (frame := reader.next()) is not None:
                self.frames.put(frame)
        except (OSError, ValueError) as e:  # stdin closed under the reader
            log.warn(f"stopped reading: {e}")
        self.frames.put(_END)

    def get(self, timeout: float | None) -> Frame | None:
        """The next frame; None when none came within `timeout` seconds or the stream ended
        (then `ended` is set)."""
        if self.ended:
            return None
        try:
            frame = self.frames.get(timeout=timeout) if timeout is None or timeout > 0 \
                else self.frames.get_nowait()
        except queue.Empty:
            return None
        if frame is _END:
            self.ended = True
        return frame


class Outbox:
    """Frames to a stream; a client that has gone is noted, not raised."""

    def __init__(self, stream: BinaryIO) -> None:
        self.stream = stream
        self.gone = False

    def write(self, data: bytes) -> None:
        if self.gone:
            return
        try:
            self.stream.write(data)
            self.stream.flush()
        except (BrokenPipeError, ValueError, OSError):
            self.gone = True


def protocol_streams() -> tuple[BinaryIO, BinaryIO]:
    """Streams on the process's stdin and stdout for the protocol alone. File descriptor 0
    then reads nothing (/dev/null), and 1 and `sys.stdout` go to stderr, so that whatever else
    would read or write there (a library's print, a child process) cannot take the client's
    frames or break the stream of the server's: it lands in the editor's log instead.

    The reader thread reads a stream of its own, not `sys.stdin`: at the interpreter's exit,
    `sys.stdin` is closed, which waits for the lock of a read under way and aborts the process."""
    sys.stdout.flush()
    streams = os.fdopen(os.dup(0), "rb"), os.fdopen(os.dup(1), "wb")
    with open(os.devnull, "rb") as nothing:
        os.dup2(nothing.fileno(), 0)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    return streams
