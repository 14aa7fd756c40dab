"""A build killed half-way (SIGTERM to its worker) fails only that model and its dependants,
leaves the previous output as it was, leaves nothing behind, and the next run completes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from tests.conftest import ERD
from tests.pipeline.helpers import env, run_json

# Waits while the file `hold` exists next to it (or until its parent, the worker, is gone),
# after writing `waiting` with its own pid (whole: the test may look at any moment): the point
# where the test kills the worker.
HOLD = """\
import os, pathlib, time
here = pathlib.Path(__file__).parent
if (here / "hold").exists():
    parent = os.getppid()
    (here / "waiting.part").write_text(str(os.getpid()))
    os.replace(here / "waiting.part", here / "waiting")
    for _ in range(1200):
        if os.getppid() != parent or not (here / "hold").exists():
            break
        time.sleep(0.05)
"""


def _write(folder: Path) -> Path:
    urdf = (ERD / "double_pendulum_description/urdf/double_pendulum.urdf").read_text()
    (folder / "slow.urdf").write_text(urdf)
    (folder / "hold.py").write_text(HOLD)
    (folder / "pipeline.yml").write_text("pipeline:\n  root: .\n  model_definitions: [slow.yml, child.yml, "
                                         "other.yml]\n")
    (folder / "slow.yml").write_text(textwrap.dedent(f"""\
        model:
          robotname: slow
          modelname: slow
          input_models: {{base: {{basefile: slow.urdf}}}}
          assemble: {{model: base}}
          post_processing:
            - cmd: ["{sys.executable}", hold.py]
              cwd: .
        """))
    (folder / "child.yml").write_text(textwrap.dedent("""\
        model:
          robotname: child
          modelname: child
          input_models: {base: {derived_base: slow.yml}}
          assemble: {model: base, name_editing: {prefix: c_}}
        """))
    (folder / "other.yml").write_text(textwrap.dedent("""\
        model:
          robotname: other
          modelname: other
          input_models:
            base: {basefile: "package://example-robot-data/robots/double_pendulum_description/urdf/double_pendulum_simple.urdf"}
          assemble: {model: base}
        """))
    return folder / "pipeline.yml"


def test_sigterm_to_a_worker_keeps_the_previous_output_and_the_next_run_completes(tmp_path: Path) -> None:
    folder = tmp_path / "p"
    folder.mkdir()
    pipeline, cache = _write(folder), tmp_path / "cache"
    first = run_json(pipeline, cache=cache)
    assert first.returncode == 0, first.stderr
    build = folder / "build"
    previous = (build / "slow/urdf/slow.urdf").read_bytes()

    urdf = folder / "slow.urdf"
    urdf.write_text(urdf.read_text().replace('value="0.10159"', 'value="0.2"', 1))
    (folder / "hold").write_text("")
    argv = [sys.executable, "-m", "mpc.cli.main", "run", str(pipeline), "--log-format", "json"]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env(cache))
    try:
        assert proc.stdout is not None
        events = []
        worker = None
        while worker is None:
            line = proc.stdout.readline()
            assert line, proc.stderr.read() if proc.stderr else ""
            events.append(json.loads(line))
            if events[-1]["event"] == "start" and events[-1]["model"] == "slow":
                worker = events[-1]["pid"]
        deadline = time.monotonic() + 120
        while not (folder / "waiting").exists():  # the build is half-way: files written, not moved
            assert time.monotonic() < deadline and proc.poll() is None
            time.sleep(0.05)
        helper = int((folder / "waiting").read_text())
        os.kill(worker, signal.SIGTERM)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    events += [json.loads(line) for line in out.splitlines()]
    assert proc.returncode == 1, err
    status = json.loads((build / ".mpc/status.json").read_text())
    slow = status["models"]["slow"]["stages"]["compile"]
    assert slow["state"] == "failed"
    assert slow["summary"] == ("the build of model 'slow' was stopped by signal SIGTERM; its previous "
                               "output is unchanged")
    assert slow["diagnostics"][0]["code"] == "E0613"
    assert status["models"]["child"]["stages"]["compile"] == {
        "state": "skipped", "reason": "derived_base 'slow' failed", "seconds": 0.0}
    assert status["models"]["other"]["stages"]["compile"]["state"] == "cached"
    assert (build / "slow/urdf/slow.urdf").read_bytes() == previous
    assert sorted(p.name for p in build.iterdir()) == [".mpc", "child", "other", "slow"]
    assert list((build / ".mpc/staging").iterdir()) == []
    assert not Path(f"/proc/{helper}").exists() or "Z" in Path(f"/proc/{helper}/stat").read_text().split()[2]

    (folder / "hold").unlink()
    again = run_json(pipeline, cache=cache)
    assert again.returncode == 0, again.stderr
    assert again.states() == {"slow": "ok", "child": "ok", "other": "cached"}
    assert b'value="0.2"' in (build / "slow/urdf/slow.urdf").read_bytes()


def test_sigterm_to_the_run_stops_its_workers_and_keeps_every_output(tmp_path: Path) -> None:
    folder = tmp_path / "p"
    folder.mkdir()
    pipeline, cache = _write(folder), tmp_path / "cache"
    assert run_json(pipeline, cache=cache).returncode == 0
    build = folder / "build"
    previous = (build / "slow/urdf/slow.urdf").read_bytes()
    (folder / "hold").write_text("")
    argv = [sys.executable, "-m", "mpc.cli.main", "run", str(pipeline), "--force", "--log-format", "json"]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env(cache))
    try:
        deadline = time.monotonic() + 120
        while not (folder / "waiting").exists():
            assert time.monotonic() < deadline and proc.poll() is None
            time.sleep(0.05)
        helper = int((folder / "waiting").read_text())
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    status = json.loads((build / ".mpc/status.json").read_text())
    assert status["models"]["slow"]["stages"]["compile"] == {
        "state": "interrupted", "reason": "the run was interrupted", "seconds": 0.0}
    assert (build / "slow/urdf/slow.urdf").read_bytes() == previous
    assert list((build / ".mpc/staging").iterdir()) == []
    assert not Path(f"/proc/{helper}").exists() or "Z" in Path(f"/proc/{helper}/stat").read_text().split()[2]
    (folder / "hold").unlink()
    again = run_json(pipeline, cache=cache)
    assert again.states() == {"slow": "cached", "child": "cached", "other": "cached"}
