"""JSON-RPC 2.0 messages: a frame's body → a request, a notification or a response, or the error
response that refuses it; and the messages the server writes.

Refusals (JSON-RPC 2.0, section 5.1):
- a body that is not UTF-8 or not JSON gets a parse error (-32700), id null;
- a body that is JSON but not a message (not an object — LSP has no batches —, no
  `"jsonrpc": "2.0"`, a method that is not a string, an id that is neither a number nor a
  string, params neither an object nor an array, neither method nor result) gets an invalid
  request (-32600), with its id when it has a valid one, else null;
- a frame the reader refused (lsp/framing.py) gets a parse error, id null.
What a well-formed message asks is the endpoint's to answer (lsp/endpoint.py).
"""

from __future__ import annotations

import json
from typing import Any

from mpc.core.record import record
from mpc.lsp.framing import Frame

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
METHOD_NOT_FOUND = -32601
INVALID_PARAMS = -32602
INTERNAL_ERROR = -32603
SERVER_NOT_INITIALIZED = -32002  # LSP's: a request before initialize
REQUEST_CANCELLED = -32800  # LSP's: the client cancelled the request

MessageId = int | str


@record
class Message:
    """A well-formed message. A request has a method and an id, a notification a method and no
    id, a response an id and no method (its result or error in `data`)."""

    data: dict[str, Any]

    @property
    def method(self) -> str | None:
        return self.data.get("method")

    @property
    def id(self) -> MessageId | None:
        return self.data.get("id")

    @property
    def is_request(self) -> bool:
        return "method" in self.data and "id" in self.data

    @property
    def params(self) -> Any:
        return self.data.get("params")


def parse(frame: Frame) -> Message | dict[str, Any]:
    """The message of a frame, or the error response that refuses it."""
    if frame.body is None:
        return error(None, PARSE_ERROR, f"message refused: {frame.problem}")
    try:
        data = json.loads(frame.body.decode("utf-8"))
    except UnicodeDecodeError as e:
        return error(None, PARSE_ERROR, f"the body is not UTF-8 (byte {e.start})")
    except ValueError as e:
        return error(None, PARSE_ERROR, f"the body is not JSON: {e}")
    problem = _not_a_message(data)
    if problem is not None:
        return error(_valid_id(data), INVALID_REQUEST, problem)
    return Message(data)


def result(message_id: MessageId, value: Any) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "id": message_id, "result": value}


def error(message_id: MessageId | None, code: int, text: str) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "id": message_id, "error": {"code": code, "message": text}}


def notification(method: str, params: Any) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "method": method, "params": params}


def encoded(message: dict[str, Any]) -> bytes:
    """A message as a frame: its Content-Length header (in bytes) and its UTF-8 body."""
    body = json.dumps(message, ensure_ascii=False, separators=(",", ":")).encode("utf-8")
    return b"Content-Length: %d\r\n\r\n%s" % (len(body), body)


def _not_a_message(data: Any) -> str | None:
    """Why a JSON value is not a JSON-RPC 2.0 message, or None if it is one."""
    if not isinstance(data, dict):
        kind = {list: "an array", str: "a string", bool: "a boolean", type(None): "null"}.get(
            type(data), "a number")
        return f"a message is a JSON object, not {kind}"
    if data.get("jsonrpc") != "2.0":
        return 'a message has "jsonrpc": "2.0"'
    if "method" in data and not isinstance(data["method"], str):
        return "a method is a string"
    if "id" in data and _valid_id(data) is None and not ("method" not in data and "error" in data):
        return "an id is a number or a string"
    if "method" not in data and ("id" not in data or not ("result" in data or "error" in data)):
        return "a message has a method (or is a response, with an id and a result or an error)"
    if not isinstance(data.get("params"), dict | list | None):  # null: as some clients send
        return "params are an object or an array"
    return None


def _valid_id(data: Any) -> MessageId | None:
    """The message's id if it is one JSON-RPC allows (a number or a string), else None."""
    value = data.get("id") if isinstance(data, dict) else None
    if isinstance(value, bool) or not isinstance(value, int | str):
        return None
    return value
