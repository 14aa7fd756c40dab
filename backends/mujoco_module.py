"""MuJoCo's Python module, imported for mpc without binding a window system.

`import mujoco` also picks a GL context class for its `Renderer`, by the MUJOCO_GL variable:
GLFW when it is not set, which loads libglfw after looking for it with `ldconfig -p` (a
process of its own): 50 ms of each import on the development machine, in every process that
reads an MJCF file or draws a model. mpc draws through EGL itself (backends/scene.py), so MuJoCo
is imported with MUJOCO_GL=disable unless the user gave a value; the environment is as it was
afterwards (it is part of what a build is kept by: compiler/build_cache.py). MuJoCo ships no
type stubs for its compiled API: the module is `Any` here.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Iterator
from typing import Any


def _imported() -> Any:
    given = os.environ.get("MUJOCO_GL")
    if given is None:
        os.environ["MUJOCO_GL"] = "disable"
    try:
        import mujoco
    finally:
        if given is None:
            os.environ.pop("MUJOCO_GL", None)
    return mujoco


mujoco: Any = _imported()


@contextlib.contextmanager
def warnings_into(said: list[str]) -> Iterator[None]:
    """MuJoCo's warnings inside the block (and Python's: a deprecated attribute) go to `said`,
    not to stdout nor to the MUJOCO_LOG.TXT that MuJoCo would append them to in the working
    folder, which is the user's, not the build's."""
    before = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: said.append(str(message).strip()))
    warned: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            warned = caught
            yield
    finally:
        mujoco.set_mju_user_warning(before)
        said += [str(w.message).strip() for w in warned]
