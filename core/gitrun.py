"""git arguments → git's output, for every git mpc runs (inputs, compare models, deploys).

One runner, so every run gets the same environment: git never prompts
(GIT_TERMINAL_PROMPT=0: a CI job has nobody to answer a credential prompt), speaks C, and
every message that leaves it has credentials scrubbed (`user:password@` in URLs, the values
of the usual token variables). It does not decide what to run; callers do.
"""

from __future__ import annotations

import os
import re
import subprocess
from collections.abc import Mapping
from pathlib import Path

# user:password@ (or token@) in URLs that git or the forge echo back.
_URL_CREDENTIALS = re.compile(r"(?P<scheme>[a-zA-Z][a-zA-Z0-9+.-]*://)(?P<user>[^/@\s:]*)(?::[^/@\s]*)?@")
# Environment variables whose values are secrets wherever they appear.
SECRET_VARIABLES = ("GITHUB_TOKEN", "GH_TOKEN", "MPC_GITHUB_TOKEN", "GITLAB_TOKEN", "CI_JOB_TOKEN",
                    "SYSTEM_ACCESSTOKEN")


class GitFailed(Exception):
    """A git run failed; `message` is git's own last complaint, scrubbed."""

    def __init__(self, args: tuple[str, ...], status: int, stderr: str) -> None:
        self.args_, self.status = args, status
        self.stderr = scrub(stderr)
        self.message = last_complaint(self.stderr) or f"git {args[0]} exited with {status}"
        super().__init__(self.message)


def scrub(text: str) -> str:
    """`text` without credentials in URLs nor the values of the secret variables."""
    text = _URL_CREDENTIALS.sub(lambda m: f"{m.group('scheme')}***@", text)
    for name in SECRET_VARIABLES:
        value = os.environ.get(name)
        if value and len(value) >= 4:
            text = text.replace(value, "***")
    return text


def without_credentials(url: str) -> str:
    """`url` without its `user:password@` (or `token@`) part: the address to write into a
    repository (`.gitmodules`) or to key clones by, since CI tokens change from job to job."""
    def keep_ssh_user(m: re.Match[str]) -> str:
        # ssh://git@host/x names the account, not a secret; any password goes all the same
        ssh = "ssh" in m.group("scheme").lower()
        return m.group("scheme") + (f"{m.group('user')}@" if ssh and m.group("user") else "")

    return _URL_CREDENTIALS.sub(keep_ssh_user, url)


def git_environment() -> dict[str, str]:
    """Variables for every git run: never prompt (a CI job has nobody to answer)."""
    return {"GIT_TERMINAL_PROMPT": "0", "LC_ALL": "C"}


def last_complaint(stderr: str) -> str:
    """git's own complaint (its last `fatal:` or `error:` line, else its last line)."""
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()]
    said = [ln for ln in lines if ln.startswith(("fatal:", "error:"))]
    return (said or lines or [""])[-1]


def result(args: tuple[str, ...] | list[str], cwd: Path | None = None,
           env: Mapping[str, str] | None = None) -> tuple[int, str, str]:
    """(status, stdout, stderr) of `git args…` in `cwd`; stderr scrubbed. Raises OSError
    only when git itself cannot be started."""
    run = subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, errors="replace",
                         env={**os.environ, **git_environment(), **(env or {})}, check=False)
    return run.returncode, run.stdout, scrub(run.stderr)


def git(*args: str, cwd: Path | None = None, env: Mapping[str, str] | None = None) -> str:
    """The output of `git args…` (without its final newline); GitFailed when it fails."""
    status, out, err = result(args, cwd, env)
    if status != 0:
        raise GitFailed(args, status, err)
    return out[:-1] if out.endswith("\n") else out
