"""The programs an output is made with → noted as files the build read, so that a kept output
(compiler/build_cache.py) is made again when one of them changes or appears.

The exports that run programs (`pdf`: Graphviz's `dot`, `kccd`: KCCD's tools, `render`:
MuJoCo drawing through EGL on Mesa) make outputs that depend on those programs as much as on
the robot. What they depend on is noted through core/reads.py (`note_files`):
- a program run as a command (`which`): its executable and the shared libraries it loads
  (`ldd`, asked once per process), so that an upgrade of Graphviz changes the key; when the
  program is not found, each place on PATH it was looked for, so that installing it does;
- a drawing in this process (`note_loaded_libraries`): every shared library mapped into the
  process from outside Python's installation (EGL, Mesa's driver, LLVM), whose versions
  Python's installed distributions do not name.
Not noted: plugins a command loads at run time that it does not link (Graphviz's plugins
are found by its own configuration); the files are noted by their bytes.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import sys
import sysconfig

from mpc.core.reads import note_files


def which(name: str) -> str | None:
    """`shutil.which(name)`, noting what the output made with it depends on (see above)."""
    found = shutil.which(name)
    if found is None:
        folders = os.environ.get("PATH", os.defpath).split(os.pathsep)
        note_files(os.path.join(os.path.abspath(folder or "."), name) for folder in folders)
    else:
        note_files((os.path.realpath(found), *_linked(os.path.realpath(found))))
    return found


@functools.cache
def _linked(executable: str) -> tuple[str, ...]:
    """The shared libraries `executable` loads, as `ldd` lists them (none when it cannot say)."""
    ldd = shutil.which("ldd")
    if ldd is None:
        return ()
    try:
        done = subprocess.run([ldd, executable], capture_output=True, text=True, check=False, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return ()
    found = (part for line in done.stdout.splitlines() for part in line.split() if part.startswith("/"))
    return tuple(sorted({os.path.realpath(path) for path in found}))


def note_loaded_libraries() -> None:
    """Note the shared libraries mapped into this process from outside Python's installation."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
            paths = {line.split(None, 5)[5].strip() for line in maps if len(line.split(None, 5)) == 6}
    except OSError:
        return
    # Python's own folders: the environment and the standard library (not sys.base_prefix,
    # which is /usr for Debian's Python, where the graphics libraries lie too)
    folders = sysconfig.get_paths()
    python = tuple({os.path.realpath(p) + os.sep for p in (
        sys.prefix, *(folders[k] for k in ("stdlib", "platstdlib", "purelib", "platlib") if k in folders))})
    note_files(sorted(p for p in paths if p.startswith("/") and ".so" in os.path.basename(p)
                      and not os.path.realpath(p).startswith(python)))
