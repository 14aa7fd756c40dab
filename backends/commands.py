"""Run a `post_processing` command in the output folder being written.

The command runs with PATH, HOME and the variables its entry lists (`env: [NAME]`) of mpc's
environment, nothing else. It sees the folder it may change (MPC_EXPORTDIR, the staging folder), where that
folder will be once the build succeeds (MPC_TARGETDIR), and the definition's folder
(MPC_DEFINITIONDIR), also under Phobos's names (PHOBOS_CI_*) so that existing scripts keep
working. A command that fails, or cannot start, fails the build with its output; the
previous output stays as it was, since nothing is swapped into place.
"""

from __future__ import annotations

import os
import shlex
import subprocess
from pathlib import Path

from mpc.core import blas
from mpc.core.diagnostics import Sink
from mpc.ir.program import CommandExport

_OUTPUT_LINES = 20  # the end of a failing command's output shown in the diagnostic


# What every command gets of mpc's environment besides what its entry lists (`env:`): where
# programs are, and the home folder some programs need to start at all.
BASE_VARIABLES = ("PATH", "HOME")


def environment(staging: Path, out: Path, definition_dir: Path,
                listed: tuple[str, ...] = ()) -> dict[str, str]:
    """The command's environment: PATH, HOME and the variables its entry lists, from mpc's
    environment as the user gave it (unset ones stay unset), and the MPC_*/PHOBOS_CI_* folders.
    Nothing else: a token in the CI job's environment reaches no command that does not ask."""
    places = {"EXPORTDIR": staging, "TARGETDIR": out, "DEFINITIONDIR": definition_dir}
    user = blas.user_environment()
    env = {name: user[name] for name in (*BASE_VARIABLES, *listed) if name in user}
    env.setdefault("PATH", os.defpath)
    for name, path in places.items():
        env[f"MPC_{name}"] = env[f"PHOBOS_CI_{name}"] = str(path.resolve())
    return env


def run(export: CommandExport, staging: Path, out: Path, sink: Sink) -> bool:
    """Run the command; False (with an error) when it fails."""
    shown = export.command[0] if export.shell else shlex.join(export.command)
    definition_dir = Path(export.span.file).resolve().parent
    cwd = definition_dir / export.cwd if export.cwd else staging
    if not cwd.is_dir():
        sink.error(export.span, "E0508", f"post_processing command `{shown}`: its cwd '{export.cwd}' is "
                   f"not a folder ({cwd})")
        return False
    try:
        done = subprocess.run(export.command[0] if export.shell else list(export.command),
                              shell=export.shell, executable=export.executable or None, cwd=cwd,
                              env=environment(staging, out, definition_dir, export.env), capture_output=True,
                              text=True, errors="replace", check=False)
    except OSError as error:
        sink.error(export.span, "E0508", f"post_processing command `{shown}` could not start: "
                   f"{error.strerror}", hint=None if export.shell else "is the program on PATH?")
        return False
    if done.returncode == 0:
        return True
    output = (done.stdout + done.stderr).rstrip().splitlines()[-_OUTPUT_LINES:]
    notes = ((None, "its output ends:\n" + "\n".join("    " + line for line in output)),) if output else ()
    sink.error(export.span, "E0508", f"post_processing command `{shown}` failed with exit status "
               f"{done.returncode}", notes=notes)
    return False
