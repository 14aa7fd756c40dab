"""Headless Chromium (Debian's `chromium`) driven through the Chrome DevTools protocol: load a
page, run a script in it, press keys, take screenshots. Only loopback addresses are opened."""

from __future__ import annotations

import base64
import json
import subprocess
import time
import urllib.request
from pathlib import Path
from typing import Any

from websockets.sync.client import connect

FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         # WebGL on the CPU (SwiftShader): what draws the page without a GPU
         "--enable-unsafe-swiftshader", "--window-size=900,640", "--remote-debugging-port=0")


class Browser:
    """One headless Chromium with a fresh profile in `profile`, and its first page."""

    def __init__(self, profile: Path) -> None:
        self.process = subprocess.Popen(["chromium", *FLAGS, f"--user-data-dir={profile}", "about:blank"],
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        active = profile / "DevToolsActivePort"
        deadline = time.monotonic() + 60
        while not (active.is_file() and len(active.read_text().splitlines()) >= 2):
            assert self.process.poll() is None, "chromium ended"
            assert time.monotonic() < deadline, "chromium opened no DevTools port"
            time.sleep(0.2)
        port = active.read_text().splitlines()[0]
        pages = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10))
        page = next(p for p in pages if p["type"] == "page")
        self.ws = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=20)
        self.next_id = 0
        self.events: list[dict[str, Any]] = []

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        return self.calls((method, params))[-1]

    def calls(self, *commands: tuple[str, dict[str, Any]]) -> list[dict[str, Any]]:
        """Send the commands at once (the page handles them in one go, not one per frame) and
        return their results in order; the events that arrive meanwhile are kept."""
        first = self.next_id + 1
        for method, params in commands:
            self.next_id += 1
            self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        results: dict[int, dict[str, Any]] = {}
        while len(results) < len(commands):
            message = json.loads(self.ws.recv(timeout=60))
            if message.get("id", 0) >= first:
                assert "error" not in message, message
                results[message["id"]] = message.get("result", {})
            else:
                self.events.append(message)
        return [results[i] for i in sorted(results)]

    def evaluate(self, script: str) -> Any:
        return self.call("Runtime.evaluate", expression=script, returnByValue=True)["result"].get("value")

    def wait_for(self, script: str, seconds: float = 60) -> Any:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            value = self.evaluate(script)
            if value:
                return value
            time.sleep(0.5)
        raise AssertionError(f"the page never made true: {script}")

    def screenshot(self) -> bytes:
        return base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])

    def press(self, key: str, code: str, key_code: int, times: int = 1) -> None:
        """Press and release a key `times` times."""
        keys = {"key": key, "code": code, "windowsVirtualKeyCode": key_code, "nativeVirtualKeyCode": key_code}
        self.calls(*(("Input.dispatchKeyEvent", {"type": kind, **keys})
                     for _ in range(times) for kind in ("keyDown", "keyUp")))

    def close(self) -> None:
        try:
            self.ws.close()
        finally:
            self.process.terminate()
            try:
                self.process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
