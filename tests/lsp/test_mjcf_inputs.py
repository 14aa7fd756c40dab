"""`mpc lsp` on a definition whose input model is an MJCF: no diagnostic for a good one,
completion of its names and of `.xml` files, go to definition into the file that holds the
element (an included one too)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.conftest import write
from tests.lsp.client import Client

TEXT = """model:
  robotname: r
  modelname: r
  input_models:
    arm:
      basefile: arm.xml
  assemble:
    model: arm
  joints:
    knee:
      damping: 0.5
  frames:
    tool:
      parent: hip
      xyz: [0, 0, 0.1]
"""


@pytest.fixture
def server(tmp_path: Path) -> Client:
    write(tmp_path / "parts" / "leg.xml", """
        <mujoco><body name="leg"><joint name="knee" axis="0 1 0"/><geom type="sphere" size="0.1"/></body>
        </mujoco>""")
    write(tmp_path / "arm.xml", """
        <mujoco model="arm">
          <worldbody><body name="hip"><geom type="sphere" size="0.1"/>
            <include file="parts/leg.xml"/></body></worldbody>
        </mujoco>""")
    client = Client(env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}, cwd=tmp_path)
    client.initialize(tmp_path)
    yield client
    assert client.close() == 0


def test_an_mjcf_input_in_the_language_server(server: Client, tmp_path: Path) -> None:
    path = tmp_path / "r.yml"
    path.write_text(TEXT, encoding="utf-8")
    uri = server.open(path)
    assert server.diagnostics(uri, 1) == []
    leg = (tmp_path / "parts" / "leg.xml").as_uri()
    found = server.request("textDocument/definition", server.at(uri, 9, 5))  # joints: knee
    assert (found["uri"], found["range"]["start"]) == (leg, {"line": 0, "character": 25})
    found = server.request("textDocument/definition", server.at(uri, 13, 15))  # parent: hip
    assert (found["uri"], found["range"]["start"]) == ((tmp_path / "arm.xml").as_uri(),
                                                       {"line": 1, "character": 13})
    items = server.request("textDocument/completion", server.at(uri, 13, 14))
    items = items["items"] if isinstance(items, dict) else items
    assert [i["label"] for i in items] == ["hip", "leg"]
