"""MuJoCo is imported for mpc without GLFW (backends/mujoco_module.py): mpc draws through EGL,
and GLFW's lookup (`ldconfig -p`) and library cost every process that reads an MJCF file 50 ms."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

PROBE = """
import os, sys
from mpc.backends.mujoco_module import mujoco
print(mujoco.__name__, "glfw" in sys.modules, os.environ.get("MUJOCO_GL", "-"))
"""


@pytest.mark.parametrize(("given", "printed"), [
    (None, "mujoco False -"),        # imported with MUJOCO_GL=disable, the environment as it was
    ("glfw", "mujoco True glfw"),    # the user's choice stands
])
def test_mujoco_is_imported_without_glfw_unless_asked_for(given: str | None, printed: str) -> None:
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    if given is not None:
        env["MUJOCO_GL"] = given
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == printed
