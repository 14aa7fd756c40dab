"""The project folder and the running mpc → how a CI job installs that same mpc (shell lines).

In order: the definitions repository's own pin (a `requirements.txt` line naming
model-pipeline-compiler, installed with uv from that file), else how this mpc was installed
(PEP 610's `direct_url.json`: a git URL at its commit, a wheel or archive URL, a wheel or
folder inside the project, a folder that is a git checkout with a remote: its remote at
HEAD), else the package index at this version. A pin of another version is E0680; an mpc
that CI cannot reach (a folder outside the project with no git remote) is E0681.

It does not run the install, nor check that a URL answers.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
from importlib import metadata
from pathlib import Path
from urllib.parse import unquote, urlparse

from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.core.version import mpc_version

DIST = "model-pipeline-compiler"
VENV = ".mpc-venv"  # where a job installs mpc, inside its checkout
# uv if the image has none; then a virtual environment with mpc, first on PATH
_UV = "command -v uv >/dev/null || python3 -m pip install --quiet uv"
_VENV = f"uv venv --quiet {VENV}"
_PATH = f'export PATH="$PWD/{VENV}/bin:$PATH"'
_NAME = re.compile(r"^\s*model[-_.]pipeline[-_.]compiler\b", re.IGNORECASE)


@record
class Install:
    """How jobs install mpc: `lines` of shell (GitLab `before_script`, one GitHub step);
    `source`, what they install from (for the generated file's header); `files`, the project
    files they read (part of the uv cache key)."""

    lines: tuple[str, ...]
    source: str
    files: tuple[str, ...] = ()


def derive(project: Path, sink: Sink) -> Install | None:
    """The install of the running mpc for jobs that check out `project`; None after an error."""
    pinned = _requirements(project, sink)
    if pinned is not None or sink.has_errors():
        return pinned
    requirement = _running(project, sink)
    if requirement is None:
        return None
    return Install((_UV, _VENV, f"uv pip install --quiet --python {VENV} {shlex.quote(requirement)}", _PATH),
                   requirement)


def given(command: str) -> Install:
    """`--install CMD`: the team's own command (it must put `mpc` on PATH)."""
    return Install((command,), command)


def version_check(version: str) -> str:
    """A shell line that stops a job whose mpc is not the one that wrote the pipeline (E0682)."""
    code = "E0682"
    return ('v="$(mpc --version 2>/dev/null || true)"; [ "$v" = "mpc $MPC_VERSION" ] || '
            f'{{ echo "error[{code}]: this pipeline was written by mpc $MPC_VERSION, but this job runs '
            '${v:-no mpc}: install mpc $MPC_VERSION (see the install step), or regenerate the '
            'pipeline with the mpc that the job installs" >&2; exit 1; }')


def _requirements(project: Path, sink: Sink) -> Install | None:
    """`requirements.txt` of the project, when a line of it names mpc."""
    path = project / "requirements.txt"
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.split(" #", 1)[0].strip()
        if not _NAME.match(stripped) and not _names_wheel(stripped):
            continue
        pinned = _pinned_version(stripped)
        if pinned is not None and pinned != mpc_version():
            col = line.find(pinned) + 1
            sink.error(Span(str(path), number, col, number, col + len(pinned)), "E0680",
                       f"requirements.txt installs mpc {pinned}, but mpc {mpc_version()} writes this "
                       "pipeline: its jobs would stop at the version check",
                       hint=f"pin mpc {mpc_version()} there, or run `mpc ci` with mpc {pinned}")
            return None
        return Install((_UV, _VENV, f"uv pip install --quiet --python {VENV} -r requirements.txt", _PATH),
                       "requirements.txt", ("requirements.txt",))
    return None


def _names_wheel(line: str) -> bool:
    return bool(re.search(r"(^|/)model_pipeline_compiler-[^/\s]+\.whl$", line, re.IGNORECASE))


def _pinned_version(line: str) -> str | None:
    """The version a requirement line fixes: `==X`, or a wheel file name's."""
    match = re.search(r"==\s*([\w.+!-]+)", line) or re.search(
        r"model_pipeline_compiler-([^-/\s]+)-[^/\s]*\.whl", line, re.IGNORECASE)
    return match.group(1) if match else None


def _running(project: Path, sink: Sink) -> str | None:
    """A requirement for the running mpc, from how it was installed."""
    try:
        raw = metadata.distribution(DIST).read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        raw = None
    return requirement(raw, project, sink)


def requirement(direct_url: str | None, project: Path, sink: Sink) -> str | None:
    """A requirement for the mpc that PEP 610's `direct_url.json` describes (None: it came
    from a package index), for jobs that check out `project`."""
    try:
        info = json.loads(direct_url) if direct_url else {}
        url: str = info["url"]
    except (ValueError, TypeError, KeyError):  # none, or not PEP 610's: as from an index
        return f"{DIST}=={mpc_version()}"  # from a package index: the team's index serves it again
    vcs = info.get("vcs_info")
    if vcs:
        return f"{DIST} @ {vcs['vcs']}+{url}@{vcs['commit_id']}"
    if not url.startswith("file:"):
        return f"{DIST} @ {url}"
    local = Path(unquote(urlparse(url).path))
    if local.resolve().is_relative_to(project.resolve()):
        return "./" + os.path.relpath(local.resolve(), project.resolve())
    remote = _git_remote(local) if local.is_dir() else None
    if remote is not None:
        return f"{DIST} @ git+{remote[0]}@{remote[1]}"
    sink.error(Span.of_file(str(local)), "E0681",
               f"CI jobs cannot install this mpc: it was installed from '{local}', which is outside the "
               "project and not a git checkout with a remote",
               hint="give `--install CMD`, or name mpc in the project's requirements.txt "
                    "(a wheel inside the project, a git URL at a commit, or an index version)")
    return None


def _git_remote(folder: Path) -> tuple[str, str] | None:
    """The fetch address of the checkout's `origin` (else its first remote) and its HEAD commit."""
    def git(*args: str) -> str:
        done = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True)
        return done.stdout.strip() if done.returncode == 0 else ""

    remotes = git("remote").split()
    if not remotes:
        return None
    remote = "origin" if "origin" in remotes else remotes[0]
    url, commit = git("remote", "get-url", remote), git("rev-parse", "HEAD")
    if not url or not commit:
        return None
    if "://" not in url and ":" in url.split("/", 1)[0]:  # scp-like git@host:group/repo.git
        host, path = url.split(":", 1)
        url = f"ssh://{host}/{path}"
    return url, commit
