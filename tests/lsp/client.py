"""A minimal LSP client over stdio: starts `mpc lsp --stdio`, sends requests and notifications,
and collects what the server publishes. For the tests of tests/lsp/ and bench/bench_lsp.py.
"""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any


class Client:
    """One server process. `request` waits for the answer; `diagnostics` waits for a publish."""

    def __init__(self, *args: str, env: dict[str, str] | None = None, cwd: Path | None = None) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "lsp", "--stdio", *args],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     env=env, cwd=cwd)
        self.next_id = 0
        self.capabilities: dict[str, Any] = {}
        self.answers: dict[int, queue.Queue[dict[str, Any]]] = {}
        self.published: queue.Queue[tuple[float, dict[str, Any]]] = queue.Queue()
        self.lock = threading.Lock()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        out = self.proc.stdout
        assert out is not None
        while True:
            length = 0
            while True:
                line = out.readline()
                if not line:
                    return
                if line in (b"\r\n", b"\n"):
                    break
                name, _, value = line.decode("ascii").partition(":")
                if name.strip().lower() == "content-length":
                    length = int(value)
            message = json.loads(out.read(length))
            if "id" in message and "method" not in message:
                with self.lock:
                    self.answers.setdefault(message["id"], queue.Queue()).put(message)
            elif message.get("method") == "textDocument/publishDiagnostics":
                self.published.put((time.perf_counter(), message["params"]))
            elif "id" in message:  # a request from the server (registrations): answer it
                self._send({"jsonrpc": "2.0", "id": message["id"], "result": None})

    def _send(self, message: dict[str, Any]) -> None:
        body = json.dumps(message).encode("utf-8")
        self.send_raw(b"Content-Length: %d\r\n\r\n" % len(body) + body)

    def send_raw(self, data: bytes) -> None:
        """Bytes as they are, framed or not."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def answered(self, number: int | str | None) -> list[dict[str, Any]]:
        """The answers with this id received so far (id None: the server's refusals of frames
        it could not read)."""
        with self.lock:
            box = self.answers.setdefault(number, queue.Queue())
        found = []
        while not box.empty():
            found.append(box.get_nowait())
        return found

    def notify(self, method: str, params: dict[str, Any] | None = None) -> None:
        self._send({"jsonrpc": "2.0", "method": method, "params": params or {}})

    def request(self, method: str, params: dict[str, Any] | None = None, timeout: float = 60) -> Any:
        self.next_id += 1
        number = self.next_id
        with self.lock:
            box = self.answers.setdefault(number, queue.Queue())
        self._send({"jsonrpc": "2.0", "id": number, "method": method, "params": params or {}})
        answer = box.get(timeout=timeout)
        if "error" in answer:
            raise RuntimeError(f"{method}: {answer['error']}")
        return answer["result"]

    def initialize(self, root: Path) -> dict[str, Any]:
        result = self.request("initialize", {"processId": None, "rootUri": root.as_uri(),
                                             "capabilities": {}})
        self.notify("initialized")
        self.capabilities = result["capabilities"]
        return result

    def open(self, path: Path, text: str | None = None) -> str:
        uri = path.as_uri()
        self.notify("textDocument/didOpen", {"textDocument": {
            "uri": uri, "languageId": "yaml", "version": 1,
            "text": path.read_text(encoding="utf-8") if text is None else text}})
        return uri

    def change(self, uri: str, version: int, text: str) -> None:
        self.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": version},
                                               "contentChanges": [{"text": text}]})

    def diagnostics(self, uri: str, version: int | None = None, timeout: float = 60) -> list[dict[str, Any]]:
        """The next diagnostics published for `uri` (of `version`, when given)."""
        return self.published_at(uri, version, timeout)[1]

    def published_at(self, uri: str, version: int | None = None,
                     timeout: float = 60) -> tuple[float, list[dict[str, Any]]]:
        """When the next diagnostics for `uri` (of `version`) arrived, and they."""
        end = time.monotonic() + timeout
        while True:
            at, params = self.published.get(timeout=max(end - time.monotonic(), 0.01))
            if params["uri"] == uri and (version is None or params.get("version") == version):
                return at, params["diagnostics"]

    def at(self, uri: str, line: int, character: int) -> dict[str, Any]:
        return {"textDocument": {"uri": uri}, "position": {"line": line, "character": character}}

    def close(self) -> int:
        """shutdown, exit; the server's exit status."""
        try:
            self.request("shutdown", timeout=10)
            self.notify("exit")
            return self.proc.wait(timeout=10)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
                self.proc.wait()
