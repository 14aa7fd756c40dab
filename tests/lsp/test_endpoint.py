"""lsp/endpoint.py in-process: the LSP lifecycle, dispatch, refusals, cancellation and the
debounce, on messages that have all arrived before the server looks (a list of frames), with
what it writes read back. (tests/lsp/test_lifecycle.py drives the real process.)"""

from __future__ import annotations

import json
import re
import shutil
from collections import deque
from pathlib import Path
from typing import Any

from mpc.lsp.endpoint import Endpoint
from mpc.lsp.framing import Frame
from mpc.lsp.server import MpcServer
from tests.lsp.definitions import EXPORT, HEAD

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"


class Arrived:
    """A source of frames that have all arrived: `get` never waits."""

    def __init__(self, messages: list[dict[str, Any]]) -> None:
        self.frames = deque(Frame(json.dumps(m).encode()) for m in messages)
        self.ended = False

    def get(self, timeout: float | None) -> Frame | None:
        if self.frames:
            return self.frames.popleft()
        self.ended = True
        return None


class Written:
    """What the server writes, as messages."""

    def __init__(self) -> None:
        self.data = b""

    def write(self, data: bytes) -> None:
        self.data += data

    def messages(self) -> list[dict[str, Any]]:
        out, rest = [], self.data
        while rest:
            header = re.match(rb"Content-Length: (\d+)\r\n\r\n", rest)
            assert header is not None, rest[:80]
            end = header.end() + int(header.group(1))
            out.append(json.loads(rest[header.end():end]))
            rest = rest[end:]
        return out


def request(number: int, method: str, params: Any = None) -> dict[str, Any]:
    return {"id": number, **notification(method, params)}


def notification(method: str, params: Any = None) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "method": method, **({} if params is None else {"params": params})}


INITIALIZE = request(1, "initialize", {"processId": None, "capabilities": {}})
SHUTDOWN = request(99, "shutdown")
EXIT = notification("exit")


def served(endpoint: Endpoint, *messages: dict[str, Any]) -> tuple[int, list[dict[str, Any]]]:
    """The exit status and what the endpoint answered (initialize's answer left out)."""
    written = Written()
    endpoint.write = written.write
    status = endpoint.run(Arrived([INITIALIZE, *messages]))
    answers = written.messages()
    assert answers[0]["id"] == 1 and "result" in answers[0]
    return status, answers[1:]


def errors(answers: list[dict[str, Any]]) -> list[tuple[Any, int, str]]:
    return [(a["id"], a["error"]["code"], a["error"]["message"]) for a in answers if "error" in a]


def endpoint() -> Endpoint:
    """An endpoint with a request that echoes and one that fails."""
    point = Endpoint(lambda data: None, "test", "1")
    point.requests["test/echo"] = lambda params: params

    def fail(params: Any) -> None:
        raise ValueError("boom")

    point.requests["test/fail"] = fail
    return point


def test_initialize_answers_the_capabilities_and_the_servers_name() -> None:
    written = Written()
    server = MpcServer(write=written.write)
    server.run(Arrived([INITIALIZE]))
    (answer,) = written.messages()
    assert answer["result"]["serverInfo"]["name"] == "mpc"
    assert answer["result"]["capabilities"]["textDocumentSync"] == {"openClose": True, "change": 2,
                                                                    "save": True}
    assert answer["result"]["capabilities"]["codeActionProvider"] == {"codeActionKinds": ["quickfix"]}


def test_before_initialize_requests_are_refused_and_notifications_dropped() -> None:
    written = Written()
    point = endpoint()
    point.write = written.write
    assert point.run(Arrived([notification("test/anything"), request(2, "test/echo", {"a": 1}), EXIT])) == 1
    assert errors(written.messages()) == [(2, -32002, "test/echo before initialize")]


def test_a_second_initialize_is_an_invalid_request() -> None:
    _, answers = served(endpoint(), INITIALIZE)
    assert errors(answers) == [(1, -32600, "initialize was received already")]


def test_unknown_methods() -> None:
    """A request of a method without a handler gets method not found; a notification of one
    (`$/` or not) is ignored."""
    _, answers = served(endpoint(), notification("$/setTrace", {"value": "off"}), notification("mpc/nothing"),
                        request(2, "mpc/nothing"), request(3, "$/something"), request(4, "test/echo", [1]))
    assert errors(answers) == [(2, -32601, "method not found: mpc/nothing"),
                               (3, -32601, "method not found: $/something")]
    assert answers[-1] == {"jsonrpc": "2.0", "id": 4, "result": [1]}


def test_invalid_params_are_named() -> None:
    server = MpcServer()
    _, answers = served(server, request(2, "textDocument/hover", {"textDocument": {"uri": 3},
                                                                  "position": {"line": -1}}),
                        request(3, "textDocument/documentSymbol"),
                        request(4, "textDocument/codeAction", {"textDocument": {"uri": "file:///a.yml"},
                                                               "range": {"start": {"line": 0, "character": 0},
                                                                         "end": {"line": 0, "character": 1}},
                                                               "context": {"diagnostics": [{"range": 1}]}}))
    assert errors(answers) == [
        (2, -32602, "invalid params of textDocument/hover: expected a string @ $.params.textDocument.uri; "
                    "expected an integer ≥ 0 @ $.params.position.line; "
                    "required field missing @ $.params.position.character"),
        (3, -32602, "invalid params of textDocument/documentSymbol: expected an object @ $.params"),
        (4, -32602, "invalid params of textDocument/codeAction: expected an object @ "
                    "$.params.context.diagnostics[0].range; required field missing @ "
                    "$.params.context.diagnostics[0].message")]


def test_a_request_on_a_buffer_that_is_not_open() -> None:
    _, answers = served(MpcServer(), request(2, "textDocument/hover", {
        "textDocument": {"uri": "file:///nowhere.yml"}, "position": {"line": 0, "character": 0}}))
    assert errors(answers) == [(2, -32602, "file:///nowhere.yml is not open (textDocument/didOpen)")]


def test_a_handlers_failure_is_an_internal_error_and_the_server_goes_on() -> None:
    _, answers = served(endpoint(), request(2, "test/fail"), request(3, "test/echo", {"b": 2}))
    assert errors(answers) == [(2, -32603, "internal error in test/fail: ValueError: boom")]
    assert answers[-1]["result"] == {"b": 2}


def test_after_shutdown_only_exit_is_served() -> None:
    status, answers = served(endpoint(), SHUTDOWN, request(2, "test/echo", {}), notification("test/x"), EXIT,
                             request(3, "test/echo", {}))
    assert status == 0
    assert answers[0] == {"jsonrpc": "2.0", "id": 99, "result": None}
    assert errors(answers) == [(2, -32600, "test/echo after shutdown: only exit is served")]
    assert len(answers) == 2  # nothing after exit


def test_the_exit_status() -> None:
    assert served(endpoint(), EXIT)[0] == 1  # exit without shutdown
    assert served(endpoint(), SHUTDOWN)[0] == 0  # the stream ends after shutdown
    assert served(endpoint())[0] == 1  # the stream ends without it


def test_a_cancelled_request_that_waited_is_answered_so() -> None:
    """The cancellation arrived while the request waited: it is not served. One for a request
    already answered, or of no request, changes nothing."""
    cancel = "$/cancelRequest"
    _, answers = served(endpoint(), request(2, "test/echo", {"c": 3}), request(3, "test/echo", {"d": 4}),
                        notification(cancel, {"id": 3}), notification(cancel, {"id": 77}),
                        notification(cancel, {"id": [1]}), request(77, "test/echo", {"e": 5}))
    assert answers[0]["result"] == {"c": 3}
    assert errors(answers) == [(3, -32800, "test/echo 3 was cancelled")]
    assert answers[-1]["result"] == {"e": 5}  # id 77 after its cancellation was served: served


def test_a_response_from_the_client_is_ignored() -> None:
    _, answers = served(endpoint(), {"jsonrpc": "2.0", "id": 5, "result": None},
                        request(2, "test/echo", [1]))
    assert answers == [{"jsonrpc": "2.0", "id": 2, "result": [1]}]


def test_changes_wait_for_the_debounce_and_a_request_checks_first(tmp_path: Path) -> None:
    """Three changes in a row are checked once (after the quiet time, or by the request that
    comes first); the request sees the last text."""
    shutil.copy(EXAMPLES / "arm.urdf", tmp_path / "arm.urdf")
    shutil.copytree(EXAMPLES / "meshes", tmp_path / "meshes")
    uri = (tmp_path / "arm.yml").as_uri()
    text = HEAD + "  joints:\n    elbo:\n      damping: 0.5\n" + EXPORT
    server = MpcServer()
    server.debounce = 60  # longer than the test: only the request can check
    changes = [notification("textDocument/didChange", {
        "textDocument": {"uri": uri, "version": v}, "contentChanges": [{"text": text.replace("elbo", name)}]})
        for v, name in ((2, "x"), (3, "y"), (4, "elbow"))]
    hover = request(2, "textDocument/hover", {"textDocument": {"uri": uri},
                                              "position": {"line": 9, "character": 6}})
    opened = notification("textDocument/didOpen", {"textDocument": {
        "uri": uri, "languageId": "yaml", "version": 1, "text": text}})
    _, answers = served(server, opened, *changes, hover)
    published = [(a["params"]["version"], [d["code"] for d in a["params"]["diagnostics"]])
                 for a in answers if a.get("method") == "textDocument/publishDiagnostics"]
    assert published == [(1, ["E0310"]), (4, [])]
    assert answers[-1]["result"]["contents"]["value"].startswith("**joint elbow** (revolute)")
