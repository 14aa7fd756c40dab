"""lsp/framing.py on byte streams where the places it must find fall on the edges of its reads:
a header cut by the end of a header-line read, a header cut by the end of a body chunk, a
stream that ends inside a body. (tests/lsp/test_malformed_input.py drives the real server.)
"""

from __future__ import annotations

import io
import json

from mpc.lsp.framing import CHUNK, MAX_LINE, Frame, FrameReader

MESSAGE = json.dumps({"jsonrpc": "2.0", "id": 1, "method": "shutdown"}).encode()
FRAME = b"Content-Length: %d\r\n\r\n" % len(MESSAGE) + MESSAGE


def frames(data: bytes) -> list[Frame]:
    reader = FrameReader(io.BufferedReader(io.BytesIO(data)))  # type: ignore[arg-type]
    out = []
    while (frame := reader.next()) is not None:
        out.append(frame)
    return out


def test_a_header_across_the_end_of_a_line_read() -> None:
    # a body sent without a header, then a frame whose header starts 4 bytes before the end of
    # the first MAX_LINE read: the skip keeps the read's tail and finds it
    skipped = b'{"text": "' + b"x" * (MAX_LINE - 4 - 12) + b'"}'
    data = b"Content-Type: application/vscode-jsonrpc\r\n\r\n" + skipped + FRAME
    assert len(skipped) == MAX_LINE - 4
    refused, served = frames(data)
    assert refused == Frame(None, "a header without Content-Length; the stream was read on to the "
                                  "next header")
    assert served == Frame(MESSAGE)


def test_a_header_across_the_end_of_a_body_chunk() -> None:
    # a length 100 bytes too large on a body that ends 3 bytes before a CHUNK boundary
    body = b'{"text": "' + b"y" * (CHUNK - 3 - 12) + b'"}'
    data = b"Content-Length: %d\r\n\r\n" % (len(body) + 100) + body + FRAME
    short, served = frames(data)
    assert short == Frame(None, f"the body ended after {len(body)} of the {len(body) + 100} bytes its "
                                "Content-Length gives, where the next header starts")
    assert served == Frame(MESSAGE)


def test_a_stream_that_ends_inside_a_body() -> None:
    assert frames(b"Content-Length: 50\r\n\r\n{}") == []
    assert frames(FRAME + b"Content-Length: 50\r\n\r\n{}") == [Frame(MESSAGE)]
