"""`mpc ARGS` for tests, run in the test's own process.

The command line is the same `main(argv)` the `mpc` script runs (cli/main.py: program), with
its stdout and stderr captured; what a separate process would add is Python's start and end
and the imports of Pinocchio, PyBullet, MuJoCo and trimesh, which a worker of the suite pays
once instead of at every call (about two seconds each). The working folder and the environment
are restored afterwards.

Commands that start processes of their own or handle signals (`run`, `ci`, `view`) still run
as a process, and so does every call a test makes through `mpc_process`.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

from mpc.cli.main import main

IN_A_PROCESS = {"run", "ci", "view"}


def mpc_process(*args: str | Path, cwd: Path | None = None,
                env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "mpc.cli.main", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=600)


def mpc(*args: str | Path, cwd: Path | None = None,
        env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    argv = [str(a) for a in args]
    if not argv or argv[0] in IN_A_PROCESS:
        return mpc_process(*argv, cwd=cwd, env=env)
    out, err = io.StringIO(), io.StringIO()
    folder, environ = os.getcwd(), dict(os.environ)
    try:
        if cwd is not None:
            os.chdir(cwd)
        if env is not None:
            os.environ.clear()
            os.environ.update(env)
        with redirect_stdout(out), redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as e:  # argparse's usage errors
                code = e.code if isinstance(e.code, int) else int(e.code is not None)
    finally:
        os.chdir(folder)
        os.environ.clear()
        os.environ.update(environ)
    return subprocess.CompletedProcess(["mpc", *argv], code, out.getvalue(), err.getvalue())
