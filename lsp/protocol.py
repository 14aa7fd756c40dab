"""The JSON-RPC layer of the server: a frame's body → a message for pygls's handlers, or an error
response. pygls 1.x parsed a body with `json.loads(…, object_hook=…)` and took anything that
came out for a message; what was not an object (`null`, `[]`, `3`, `"x"`) raised inside its
reader, and a request whose params did not fit its method got no answer at all.

Here (JSON-RPC 2.0, section 5.1):
- a body that is not UTF-8 or not JSON gets a parse error (-32700), id null;
- a body that is JSON but not a message (not an object, no `"jsonrpc": "2.0"`, a method that is
  not a string, an id that is neither a number nor a string, neither method nor result) gets an
  invalid request (-32600), with its id when it has a valid one, else null;
- a request whose params do not fit its method gets invalid params (-32602) with its id, the
  message saying which fields (cattrs's words); such a notification is dropped (logged), as a
  notification has no one to answer; a request of a method the server does not have gets
  method not found (-32601), as from pygls, but without a traceback in the log;
- a frame the reader refused (lsp/framing.py) gets a parse error, id null.
The server goes on serving after each.
"""

from __future__ import annotations

import json
import logging
from typing import Any

from cattrs import transform_error
from cattrs.errors import ClassValidationError
from lsprotocol.types import ResponseErrorMessage
from pygls.exceptions import JsonRpcInternalError
from pygls.protocol import (
    JsonRPCNotification,
    JsonRPCRequestMessage,
    JsonRPCResponseMessage,
    LanguageServerProtocol,
)

from mpc.lsp.framing import Frame

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
INVALID_PARAMS = -32602
METHOD_NOT_FOUND = -32601

logger = logging.getLogger(__name__)


class MpcProtocol(LanguageServerProtocol):
    """pygls's protocol, fed whole frames by `receive` instead of bytes by `data_received`."""

    def receive(self, frame: Frame) -> None:
        """Handle one frame: serve its message, or answer why it is not one."""
        if frame.body is None:
            self.refuse(None, PARSE_ERROR, f"message refused: {frame.problem}")
            return
        if frame.problem:
            logger.warning("served a message despite %s", frame.problem)
        try:
            data = json.loads(frame.body.decode("utf-8"))
        except UnicodeDecodeError as e:
            self.refuse(None, PARSE_ERROR, f"the body is not UTF-8 (byte {e.start})")
            return
        except ValueError as e:
            self.refuse(None, PARSE_ERROR, f"the body is not JSON: {e}")
            return
        problem = _not_a_message(data)
        if problem is not None:
            self.refuse(_valid_id(data), INVALID_REQUEST, problem)
            return
        try:
            message = self._structured(data)
        except Exception as e:  # cattrs's errors: the params do not fit the method's type
            why = "; ".join(transform_error(e)) if isinstance(e, ClassValidationError) else str(e)
            if "method" in data and "id" in data:
                self.refuse(data["id"], INVALID_PARAMS, f"invalid params of {data['method']}: {why}")
            else:
                logger.warning("dropped a %s: %s", data.get("method", "response"), why)
            return
        if "method" in data and "id" in data and not self._handles(data["method"]):
            self.refuse(data["id"], METHOD_NOT_FOUND, f"method not found: {data['method']}")
            return
        try:
            self._procedure_handler(message)
        except Exception as error:  # a handler's fault must not end the server (as in pygls)
            logger.exception("error handling a message")
            self._server._report_server_error(error, JsonRpcInternalError)

    def _structured(self, data: dict[str, Any]) -> Any:
        """The message as pygls's handlers take it: lsprotocol's type for its method (pygls's
        generic one for a method it does not know), or the answer to one of the server's
        requests. (pygls's `_deserialize_message` does the same, but logs every message that
        does not fit with a traceback.)"""
        if "method" in data:
            data.setdefault("params", None)  # JSON-RPC lets it out; pygls's generic message needs it
            generic = JsonRPCRequestMessage if "id" in data else JsonRPCNotification
            return self._converter.structure(data, self.get_message_type(data["method"]) or generic)
        if "error" in data:
            return self._converter.structure(data, ResponseErrorMessage)
        answer = self._result_types.pop(data["id"], None) or JsonRPCResponseMessage
        return self._converter.structure(data, answer)

    def _handles(self, method: str) -> bool:
        """Whether a request of `method` has a handler (pygls answers one that has none, but
        logs it with a traceback)."""
        return method in self.fm.builtin_features or method in self.fm.features

    def refuse(self, message_id: int | str | None, code: int, text: str) -> None:
        """Answer a message that cannot be served; the server goes on."""
        logger.warning("%s", text)
        self._send_data({"jsonrpc": "2.0", "id": message_id, "error": {"code": code, "message": text}})


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


def _valid_id(data: Any) -> int | str | None:
    """The message's id if it is one JSON-RPC allows (a number or a string), else None."""
    value = data.get("id") if isinstance(data, dict) else None
    if isinstance(value, bool) or not isinstance(value, int | str):
        return None
    return value
