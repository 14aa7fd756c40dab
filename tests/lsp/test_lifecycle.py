"""The real `mpc lsp` process: its exit status (LSP: 0 after shutdown, else 1), its stdout kept for
the protocol, and what it does without (lsp/endpoint.py, lsp/transport.py, cli/lsp.py)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.lsp.client import Client
from tests.lsp.definitions import EXPORT, HEAD
from tests.lsp.test_malformed_input import body, framed

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"


def test_exit_without_shutdown_is_status_1(tmp_path: Path) -> None:
    client = Client(cwd=tmp_path)
    client.initialize(tmp_path)
    client.notify("exit")
    assert client.proc.wait(timeout=30) == 1


def test_the_end_of_stdin_is_status_0_after_shutdown_else_1(tmp_path: Path) -> None:
    for shutdown, status in ((True, 0), (False, 1)):
        client = Client(cwd=tmp_path)
        client.initialize(tmp_path)
        if shutdown:
            client.request("shutdown")
        assert client.proc.stdin is not None
        client.proc.stdin.close()
        assert client.proc.wait(timeout=30) == status


HOOK = """\
import atexit, os, sys

def _noise(event, args):
    if event == "open" and str(args[0]).endswith("arm.urdf"):
        print("noise from print")
        os.write(1, b"noise on descriptor 1\\n")

def _modules():
    with open(os.environ["MPC_TEST_MODULES"], "w") as f:
        f.write("\\n".join(name for name, module in sys.modules.items() if module is not None))

sys.addaudithook(_noise)
atexit.register(_modules)
"""


def test_stray_output_goes_to_stderr_and_the_libraries_the_server_does_without(tmp_path: Path) -> None:
    """What mpc or a library prints while the server runs (here: each time arm.urdf is opened)
    lands on stderr, not among the frames; and the server's process, having checked a
    definition with an expression, has imported neither pygls, lsprotocol, cattrs, asyncio,
    logging nor lark, and has not mapped OpenSSL's libcrypto (cli/lsp.py)."""
    for name in ("arm.urdf", "meshes"):
        (shutil.copytree if name == "meshes" else shutil.copy)(EXAMPLES / name, tmp_path / name)
    (tmp_path / "hook").mkdir()
    (tmp_path / "hook" / "sitecustomize.py").write_text(HOOK, encoding="utf-8")
    modules = tmp_path / "modules.txt"
    paths = [str(tmp_path / "hook"), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache"), "MPC_TEST_MODULES": str(modules),
           "PYTHONPATH": os.pathsep.join(paths)}
    client = Client(env=env, cwd=tmp_path)
    client.initialize(tmp_path)
    path = tmp_path / "arm_model.yml"
    path.write_text(HEAD + "  joints:\n    elbw:\n      max: 2*pi/3\n" + EXPORT, encoding="utf-8")
    uri = client.open(path)
    assert [d["code"] for d in client.diagnostics(uri, 1)] == ["E0310"]
    maps = Path(f"/proc/{client.proc.pid}/maps").read_text()
    assert client.close() == 0
    assert client.proc.stderr is not None
    log = client.proc.stderr.read().decode()
    assert "noise from print\n" in log and "noise on descriptor 1\n" in log
    imported = set(modules.read_text(encoding="utf-8").split("\n"))
    assert {"mpc.lsp.server", "mpc.compiler.expr_syntax"} <= imported
    assert not {"pygls", "lsprotocol", "cattrs", "asyncio", "logging", "lark", "_hashlib"} & imported
    assert "libcrypto" not in maps


def test_a_frame_refused_before_initialize_and_requests_after_shutdown(tmp_path: Path) -> None:
    client = Client(cwd=tmp_path)
    client.send_raw(framed(body({"jsonrpc": "2.0", "id": 7, "method": "textDocument/hover", "params": {}})))
    client.initialize(tmp_path)
    client.request("shutdown")
    client.send_raw(framed(body({"jsonrpc": "2.0", "id": 8, "method": "shutdown"})))
    client.notify("exit")
    assert client.proc.wait(timeout=30) == 0
    client.reader.join(timeout=30)  # it has read all the server wrote
    assert [a["error"] for a in client.answered(7)] == [
        {"code": -32002, "message": "textDocument/hover before initialize"}]
    assert [a["error"] for a in client.answered(8)] == [
        {"code": -32600, "message": "shutdown after shutdown: only exit is served"}]


def test_the_heap_is_trimmed_by_glibcs_function() -> None:
    """core/heap.py, which the server trims its heap with after each check, finds malloc_trim on
    a glibc system (elsewhere it does nothing)."""
    import platform

    from mpc.core import heap

    if platform.libc_ver()[0] != "glibc":
        pytest.skip("not glibc")
    libc = heap._libc()
    assert libc is not None and libc.malloc_trim is not None and libc.mallopt is not None
    heap.give_back()
