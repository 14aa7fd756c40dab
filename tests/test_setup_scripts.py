"""The scripts that set mpc up, lock, build and test it run uv trusting the system's
certificate store: behind a TLS-inspecting proxy whose CA is installed there (as pip and curl
trust it), uv's own bundled roots fail with "invalid peer certificate: UnknownIssuer"."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
UV_CALL = re.compile(r'^[^#]*("\$uv"|"\$tools/bin/uv"|\buv (sync|build|lock|pip|venv|export))', re.M)


def test_every_script_that_runs_uv_trusts_the_system_certificates() -> None:
    callers = {}
    for script in sorted((ROOT / "scripts").glob("*.sh")):
        text = script.read_text()
        first = UV_CALL.search(text)
        if first is not None:
            callers[script.name] = re.search(r"^export UV_SYSTEM_CERTS=1\b", text[:first.start()],
                                             re.M) is not None
    assert callers == {"check_wheel.sh": True, "lock.sh": True, "setup.sh": True}


def test_setup_takes_only_dev_as_argument() -> None:
    done = subprocess.run(["bash", str(ROOT / "scripts/setup.sh"), "--tests"], capture_output=True, text=True)
    assert (done.returncode, done.stderr) == (2, "usage: bash scripts/setup.sh [--dev]\n")
