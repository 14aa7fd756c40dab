"""`mpc schema` in a real editor client: the YAML language server from npm hovers and checks with it.

A definition names the committed schema in its first line, as users do; the server is
driven over stdio with plain JSON-RPC. Hover over a key shows its description from specs/
(under the key's name, not `Eff || Eff`), and a misspelt key is flagged.
"""

from __future__ import annotations

import json
import queue
import shutil
import subprocess
import threading
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = ROOT / "specs/model-definition.schema.json"

DEFINITION = """\
# yaml-language-server: $schema={schema}
model:
  robotname: arm
  modelname: arm-model
  input_models:
    arm: {{basefile: arm.urdf}}
  assemble:
    model: arm
  reduce_mesh: 0.5
  joints:
    elbow:
      eff: 12
  export_config:
    - type: urdf
      mesh_format: stl
"""


class Client:
    """A minimal LSP client over a subprocess's stdio."""

    def __init__(self, command: list[str]) -> None:
        self.proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL)
        self.next_id = 0
        self.notes: list[dict[str, Any]] = []
        self.inbox: queue.Queue[dict[str, Any]] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        while True:
            length = 0
            while (line := self.proc.stdout.readline()).strip():
                if line.lower().startswith(b"content-length:"):
                    length = int(line.split(b":")[1])
            if not line:
                return
            self.inbox.put(json.loads(self.proc.stdout.read(length)))

    def send(self, message: dict[str, Any]) -> None:
        body = json.dumps({"jsonrpc": "2.0", **message}).encode()
        assert self.proc.stdin is not None
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n%s" % (len(body), body))
        self.proc.stdin.flush()

    def receive(self) -> dict[str, Any]:
        return self.inbox.get(timeout=30)  # a server that stops answering fails the test

    def request(self, method: str, params: Any) -> Any:
        self.next_id += 1
        self.send({"id": self.next_id, "method": method, "params": params})
        while True:
            msg = self.receive()
            if msg.get("id") == self.next_id and "method" not in msg:
                return msg.get("result")
            if "method" in msg and "id" in msg:  # the server asks (configuration, registration)
                self.send({"id": msg["id"], "result": [{"validate": True, "hover": True,
                                                         "completion": True}]
                           if msg["method"] == "workspace/configuration" else None})
            else:
                self.notes.append(msg)

    def diagnostics(self, uri: str) -> list[dict[str, Any]]:
        while True:
            for note in self.notes:
                if note.get("method") == "textDocument/publishDiagnostics" and \
                        note["params"]["uri"] == uri and note["params"]["diagnostics"]:
                    return note["params"]["diagnostics"]
            msg = self.receive()
            if "method" in msg and "id" in msg:
                self.send({"id": msg["id"], "result": None})
            else:
                self.notes.append(msg)

    def close(self) -> None:
        self.request("shutdown", None)
        self.send({"method": "exit"})
        self.proc.wait(timeout=10)


def _hover(client: Client, uri: str, text: str, line_text: str) -> str:
    line = text.split("\n").index(line_text)
    column = len(line_text) - len(line_text.lstrip()) + 1
    result = client.request("textDocument/hover", {"textDocument": {"uri": uri},
                                                    "position": {"line": line, "character": column}})
    assert result is not None, f"no hover over {line_text.strip()!r}"
    contents = result["contents"]
    return contents["value"] if isinstance(contents, dict) else str(contents)


def test_the_yaml_language_server_hovers_with_specs_text_and_flags_typos(tmp_path: Path) -> None:
    server = shutil.which("yaml-language-server")
    assert server, "scripts/setup.sh installs yaml-language-server from npm"
    text = DEFINITION.format(schema=SCHEMA.as_uri())
    path = tmp_path / "arm.yml"
    path.write_text(text)
    uri = path.as_uri()
    client = Client([server, "--stdio"])
    try:
        client.request("initialize", {"processId": None, "rootUri": tmp_path.as_uri(),
                                      "capabilities": {"textDocument": {"hover": {
                                          "contentFormat": ["markdown", "plaintext"]}}}})
        client.send({"method": "initialized", "params": {}})
        client.send({"method": "workspace/didChangeConfiguration", "params": {"settings": {
            "yaml": {"validate": True, "hover": True, "schemaStore": {"enable": False}}}}})
        client.send({"method": "textDocument/didOpen", "params": {"textDocument": {
            "uri": uri, "languageId": "yaml", "version": 1, "text": text}}})
        eff = _hover(client, uri, text, "      eff: 12")
        mesh = _hover(client, uri, text, "      mesh_format: stl")
        diagnostics = client.diagnostics(uri)
    finally:
        client.close()
    assert eff.startswith("#### eff\n") and "effort and velocity limits" in eff and "||" not in eff, eff
    assert "format of the referenced meshes" in mesh and "Default: `input_type`" in mesh, mesh
    assert "UrdfExport" not in mesh
    typo = text.split("\n").index("  reduce_mesh: 0.5")
    assert [d for d in diagnostics if d["range"]["start"]["line"] == typo], diagnostics
