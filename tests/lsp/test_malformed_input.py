"""`mpc lsp` survives what a broken or hostile client sends (issue 35.5): after each malformed
frame, body or header, the real server answers the refusal JSON-RPC prescribes (or drops the
frame) and then answers a valid hover exactly. Before lsp/framing.py and lsp/protocol.py, pygls's
reader stopped answering for good after a `null` body or a header without a usable
Content-Length.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from mpc.lsp.framing import MAX_LINE
from tests.lsp.client import Client
from tests.lsp.definitions import EXPORT, HEAD

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"
DEFINITION = HEAD + "  frames:\n    upper:\n      name_editing:\n        suffix: _arm\n" + EXPORT
UPPER = ("**link upper**\n\nmass: 1 kg\n\nparent joint: shoulder (revolute)\n\n"
         "pose in the root frame: xyz [0, 0, 0.1], rpy [0, 0, 0]\n\narm.urdf:20")
PARSE, INVALID, PARAMS = -32700, -32600, -32602


def body(message: object) -> bytes:
    return json.dumps(message).encode()


def framed(data: bytes, header: bytes | None = None) -> bytes:
    return (b"Content-Length: %d\r\n" % len(data) if header is None else header) + b"\r\n" + data


SHUTDOWN = body({"jsonrpc": "2.0", "id": 500, "method": "shutdown"})
# The body of the frames whose header is broken: a request, answered only if it is read
REQUEST = body({"jsonrpc": "2.0", "id": 600, "method": "mpc/no-such-method"})
UNKNOWN = -32601

# name → (the bytes sent, the refusals expected with id null, the other answers expected: id → code)
FRAMES: dict[str, tuple[bytes, list[int], dict[int, int]]] = {
    "null": (framed(b"null"), [INVALID], {}),
    "empty array": (framed(b"[]"), [INVALID], {}),
    "batch": (framed(b"[" + SHUTDOWN + b"]"), [INVALID], {}),  # LSP has no batches: not shut down
    "number": (framed(b"42"), [INVALID], {}),
    "string": (framed(b'"hover"'), [INVALID], {}),
    "boolean": (framed(b"true"), [INVALID], {}),
    "not UTF-8": (framed(b'{"jsonrpc": "2.0", "method": "\xff\xfe"}'), [PARSE], {}),
    "not UTF-8 at the start": (framed(b"\xff\xfe\x00{"), [PARSE], {}),
    "truncated JSON": (framed(b'{"jsonrpc": "2.0", "id": 7'), [PARSE], {}),
    "empty body": (framed(b""), [PARSE], {}),
    "empty object": (framed(b"{}"), [INVALID], {}),
    "JSON-RPC 1.0": (framed(body({"jsonrpc": "1.0", "id": 5, "method": "shutdown"})), [], {5: INVALID}),
    "object id": (framed(body({"jsonrpc": "2.0", "id": {"a": 1}, "method": "shutdown"})), [INVALID], {}),
    "numeric method": (framed(body({"jsonrpc": "2.0", "id": 6, "method": 42})), [], {6: INVALID}),
    "string params": (framed(body({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": "x"})),
                      [INVALID], {}),
    "params of the wrong shape": (framed(body({"jsonrpc": "2.0", "id": 8, "method": "textDocument/hover",
                                               "params": {"textDocument": 3}})), [], {8: PARAMS}),
    "notification of the wrong shape": (framed(body({"jsonrpc": "2.0", "method": "textDocument/didChange",
                                                     "params": {"contentChanges": 1}})), [], {}),
    "no Content-Length": (framed(REQUEST, b"Content-Type: application/vscode-jsonrpc; charset=utf-8\r\n"),
                          [PARSE], {}),
    "non-numeric length": (framed(REQUEST, b"Content-Length: abc\r\n"), [PARSE], {}),
    "negative length": (framed(REQUEST, b"Content-Length: -5\r\n"), [PARSE], {}),
    "huge length": (framed(REQUEST, b"Content-Length: 99999999999999999999\r\n"), [PARSE], {}),
    "length too long": (framed(REQUEST, b"Content-Length: %d\r\n" % (len(REQUEST) + 300)), [PARSE], {}),
    "length too short": (framed(REQUEST, b"Content-Length: 10\r\n"), [PARSE], {}),
    "two lengths": (framed(REQUEST, b"Content-Length: 5\r\nContent-Length: %d\r\n" % len(REQUEST)),
                    [PARSE], {}),
    "latin-1 charset": (framed(REQUEST, b"Content-Length: %d\r\nContent-Type: application/vscode-jsonrpc; "
                                        b"charset=latin-1\r\n" % len(REQUEST)), [PARSE], {}),
    "garbage header only": (framed(REQUEST, b"\x00garbage\r\n"), [PARSE], {}),
    "garbage line before a good header": (b"garbage\r\n" + framed(REQUEST), [], {600: UNKNOWN}),
    "no blank line after the header": (b"Content-Length: %d\r\n" % len(REQUEST) + REQUEST, [], {}),
    "header line longer than a read": (framed(REQUEST, b"X" * (3 * MAX_LINE) + b"\r\n"), [PARSE], {}),
    "line feeds only": (b"Content-Length: %d\n\n" % len(REQUEST) + REQUEST, [], {600: UNKNOWN}),
    "body without any header": (REQUEST, [], {}),
}


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> tuple[Client, str]:
    work = tmp_path_factory.mktemp("malformed")
    shutil.copy(EXAMPLES / "arm.urdf", work / "arm.urdf")
    shutil.copytree(EXAMPLES / "meshes", work / "meshes")
    (work / "arm.yml").write_text(DEFINITION, encoding="utf-8")
    client = Client(env={**os.environ, "MPC_CACHE_DIR": str(work / "cache")}, cwd=work)
    client.next_id = 1000  # the client's own requests never take the ids of the frames below
    client.initialize(work)
    uri = client.open(work / "arm.yml")
    assert client.diagnostics(uri, 1) == []
    yield client, uri
    client.send_raw(framed(SHUTDOWN) + framed(body({"jsonrpc": "2.0", "method": "exit"})))
    assert client.proc.wait(timeout=30) == 0
    assert client.proc.stderr is not None
    log = client.proc.stderr.read().decode()
    # One line per refusal, never a traceback. (Which refusals this server saw depends on how
    # pytest-xdist shared the cases among its workers: each worker has its own server.)
    assert "Traceback" not in log


def test_there_are_twenty_kinds_of_malformed_frame() -> None:
    assert len(FRAMES) >= 20


@pytest.mark.parametrize("name", list(FRAMES))
def test_the_server_answers_after_a_malformed_frame(served: tuple[Client, str], name: str) -> None:
    client, uri = served
    data, refusals, answers = FRAMES[name]
    client.send_raw(data)
    hover = client.request("textDocument/hover", client.at(uri, 9, 6), timeout=30)
    assert hover["contents"]["value"] == UPPER
    expected = {None: refusals, **{number: [code] for number, code in answers.items()}}
    for number in (None, 5, 6, 8, 500, 600):
        assert [answer["error"]["code"] for answer in client.answered(number)] == expected.get(number, [])
