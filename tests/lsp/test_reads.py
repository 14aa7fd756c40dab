"""`mpc lsp` keeps its input models: keystrokes re-read no URDF, a change to the URDF's file
does. The server is the real one over stdio; a `sitecustomize` module on its PYTHONPATH adds
an audit hook that logs every file it opens, which is all the test looks at."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from tests.lsp.client import Client
from tests.lsp.definitions import EXPORT, HEAD

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"

HOOK = """\
import os, sys

_fd = os.open(os.environ["MPC_TEST_OPEN_LOG"], os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)

def _log(event, args, _write=os.write, _fs=os.fsencode, _fspath=os.fspath):
    if event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        _write(_fd, _fs(_fspath(args[0])) + b"\\n")  # a write to an open descriptor: no event

sys.addaudithook(_log)
"""


def test_keystrokes_reread_no_urdf_and_a_changed_urdf_is_read_again(tmp_path: Path) -> None:
    for name in ("arm.urdf", "meshes"):
        (shutil.copytree if name == "meshes" else shutil.copy)(EXAMPLES / name, tmp_path / name)
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(HOOK, encoding="utf-8")
    log = tmp_path / "opened.txt"
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache"), "MPC_TEST_OPEN_LOG": str(log),
           "PYTHONPATH": os.pathsep.join([str(hook), *filter(None, [os.environ.get("PYTHONPATH")])])}
    urdf = str(tmp_path / "arm.urdf")

    def reads() -> int:
        return log.read_text(encoding="utf-8").splitlines().count(urdf) if log.exists() else 0

    server = Client(env=env, cwd=tmp_path)
    try:
        server.initialize(tmp_path)
        text = HEAD + "  joints:\n    shoulder:\n      damping: 0.1\n" + EXPORT
        path = tmp_path / "arm_model.yml"
        path.write_text(text, encoding="utf-8")
        uri = server.open(path)
        assert server.diagnostics(uri, 1) == []
        first = reads()
        assert first >= 1  # the hook sees the server's reads

        for version in range(2, 12):  # keystrokes: a damping of 0.1, 0.11, 0.111, …
            text = text.replace("damping: 0.1", "damping: 0.11")
            server.change(uri, version, text)
            assert server.diagnostics(uri, version) == []
        assert reads() == first

        with open(urdf, "a", encoding="utf-8") as f:  # the URDF changes on disk
            f.write("<!-- edited -->\n")
        server.change(uri, 12, text.replace("damping: 0.1", "damping: 0.2"))
        assert server.diagnostics(uri, 12) == []
        assert reads() > first
    finally:
        assert server.close() == 0


def test_the_server_runs_no_post_processing_command(tmp_path: Path) -> None:
    """Opening a definition (as an editor does on a checkout of a merge request) runs none of
    its commands (issue 35.7)."""
    for name in ("arm.urdf", "meshes"):
        (shutil.copytree if name == "meshes" else shutil.copy)(EXAMPLES / name, tmp_path / name)
    canary = tmp_path / "canary"
    server = Client(env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}, cwd=tmp_path)
    try:
        server.initialize(tmp_path)
        path = tmp_path / "arm_model.yml"
        path.write_text(HEAD + EXPORT + f"  post_processing:\n    - cmd: [touch, '{canary}']\n"
                        f"    - cmd: 'touch {canary}'\n      shell: true\n", encoding="utf-8")
        uri = server.open(path)
        assert server.diagnostics(uri, 1) == []
    finally:
        assert server.close() == 0
    assert not canary.exists()
