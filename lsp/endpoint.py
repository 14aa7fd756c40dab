"""The JSON-RPC side of a language server: the LSP lifecycle, requests and notifications handed to
their handlers, cancellation, and timers (the debounce), on one thread.

The lifecycle (LSP 3.17, "Lifecycle Messages"):
- before `initialize`, a request gets -32002 (server not initialized) and a notification is
  dropped, `exit` excepted; a second `initialize` gets -32600 (invalid request);
- after `shutdown`, a request gets -32600 and a notification is dropped, `exit` excepted;
- `exit` ends the server with status 0 after `shutdown`, else 1; so does the end of stdin.
A request of a method without a handler gets -32601 (method not found); a notification of one
is ignored. Params that do not fit their method (lsp/params.py) get -32602 (invalid params)
naming the fields, or for a notification are dropped. A handler's failure gets -32603 (internal
error) for a request; the server goes on. A request that a `$/cancelRequest` read before the
request was served names gets -32800 (request cancelled) instead of being served: the frames
that arrived while the server was busy are read (lsp/transport.py) before each request is
served.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Hashable
from typing import Any, Protocol

from mpc.lsp import log, protocol
from mpc.lsp import params as shapes
from mpc.lsp.framing import Frame
from mpc.lsp.protocol import Message, MessageId

Handler = Callable[[Any], Any]


class Source(Protocol):
    """Where frames come from (lsp/transport.py's Inbox)."""

    ended: bool

    def get(self, timeout: float | None) -> Frame | None: ...


class RequestError(Exception):
    """What a request handler raises to answer with an error response."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = message


class Endpoint:
    """Messages in, answers out. `requests` and `notifications`: the handlers by method, each
    given the message's params (checked against lsp/params.py's shape of the method)."""

    def __init__(self, write: Callable[[bytes], None], name: str, version: str) -> None:
        self.write = write
        self.info = {"name": name, "version": version}
        self.capabilities: dict[str, Any] = {}
        self.requests: dict[str, Handler] = {"initialize": self._initialize, "shutdown": self._shutdown}
        self.notifications: dict[str, Handler] = {"$/cancelRequest": self._cancel_served}
        self.initialized = False
        self.shut_down = False
        self.exit_code: int | None = None
        self.timers: dict[Hashable, tuple[float, Callable[[], object]]] = {}
        self.cancelled: set[MessageId] = set()  # ids whose cancellation was read, not yet served
        self.queue: deque[Message | dict[str, Any]] = deque()

    # what handlers use

    def notify(self, method: str, params: Any) -> None:
        self.write(protocol.encoded(protocol.notification(method, params)))

    def later(self, key: Hashable, delay: float, action: Callable[[], object]) -> None:
        """Run `action` after `delay` seconds (the timer of `key` replaced, if any)."""
        self.timers[key] = (time.monotonic() + delay, action)

    def cancel_timer(self, key: Hashable) -> None:
        self.timers.pop(key, None)

    # the loop

    def run(self, source: Source) -> int:
        """Serve the frames of `source` until `exit` or its end; the exit status."""
        while self.exit_code is None:
            if not self.queue:
                frame = source.get(self._until_timer())
                if frame is None:
                    if source.ended:
                        return 0 if self.shut_down else 1
                    self._run_timers()
                    continue
                self._take(frame)
            while (frame := source.get(0)) is not None:  # what came meanwhile: cancellations
                self._take(frame)
            self.serve(self.queue.popleft())
            self._run_timers()
        return self.exit_code

    def _take(self, frame: Frame) -> None:
        if frame.body is not None and frame.problem:
            log.warn(f"served a message despite {frame.problem}")
        item = protocol.parse(frame)
        if isinstance(item, Message) and item.method == "$/cancelRequest" and item.id is None \
                and not shapes.problems("$/cancelRequest", item.params):
            self.cancelled.add(item.params["id"])
        self.queue.append(item)

    def _until_timer(self) -> float | None:
        if not self.timers:
            return None
        return max(min(due for due, _ in self.timers.values()) - time.monotonic(), 0)

    def _run_timers(self) -> None:
        now = time.monotonic()
        for key, (due, action) in list(self.timers.items()):
            if due <= now and self.timers.get(key, (None,))[0] == due:
                del self.timers[key]
                try:
                    action()
                except Exception:
                    log.fault("error in a timer's action")

    # one message

    def serve(self, item: Message | dict[str, Any]) -> None:
        """Answer one message, or send the refusal of a frame that was none."""
        if not isinstance(item, Message):
            log.warn(item["error"]["message"])
            self.write(protocol.encoded(item))
        elif item.method is None:
            log.warn(f"ignored a response to no request of the server's (id {item.id!r})")
        elif item.is_request:
            self._request(item.method, item.data["id"], item.params)
        else:
            self._notification(item.method, item.params)

    def _request(self, method: str, message_id: MessageId, params: Any) -> None:
        try:
            answer = protocol.result(message_id, self._answer(method, message_id, params))
        except RequestError as e:
            log.warn(e.message)
            answer = protocol.error(message_id, e.code, e.message)
        except Exception as e:
            log.fault(f"error in {method}")
            answer = protocol.error(message_id, protocol.INTERNAL_ERROR,
                                    f"internal error in {method}: {type(e).__name__}: {e}")
        self.write(protocol.encoded(answer))

    def _answer(self, method: str, message_id: MessageId, params: Any) -> Any:
        if message_id in self.cancelled:
            self.cancelled.discard(message_id)
            raise RequestError(protocol.REQUEST_CANCELLED, f"{method} {message_id!r} was cancelled")
        if self.shut_down:
            raise RequestError(protocol.INVALID_REQUEST, f"{method} after shutdown: only exit is served")
        if method == "initialize" and self.initialized:
            raise RequestError(protocol.INVALID_REQUEST, "initialize was received already")
        if not self.initialized and method != "initialize":
            raise RequestError(protocol.SERVER_NOT_INITIALIZED, f"{method} before initialize")
        handler = self.requests.get(method)
        if handler is None:
            raise RequestError(protocol.METHOD_NOT_FOUND, f"method not found: {method}")
        problems = shapes.problems(method, params)
        if problems:
            raise RequestError(protocol.INVALID_PARAMS, f"invalid params of {method}: {'; '.join(problems)}")
        return handler(params)

    def _notification(self, method: str, params: Any) -> None:
        if method == "exit":
            self.exit_code = 0 if self.shut_down else 1
            return
        handler = self.notifications.get(method)
        if handler is None or not self.initialized or self.shut_down:
            if handler is not None:
                log.warn(f"dropped a {method} {'after shutdown' if self.shut_down else 'before initialize'}")
            return
        problems = shapes.problems(method, params)
        if problems:
            log.warn(f"dropped a {method}: {'; '.join(problems)}")
            return
        try:
            handler(params)
        except Exception:
            log.fault(f"error in {method}")

    def _initialize(self, params: Any) -> dict[str, Any]:
        self.initialized = True
        return {"capabilities": self.capabilities, "serverInfo": self.info}

    def _shutdown(self, params: Any) -> None:
        self.shut_down = True
        self.timers.clear()

    def _cancel_served(self, params: dict[str, Any]) -> None:
        """The request a cancellation names was read before it, and so has been served."""
        self.cancelled.discard(params["id"])
