"""Running git (through GitPython) in one repository, with credentials kept out of messages.

`Git(folder)` runs `git <args>` there and returns its output; a failure raises
`DeployError` with git's own message, after `scrub` removed passwords and tokens. Git never
prompts (GIT_TERMINAL_PROMPT=0): credentials come from the environment or git's credential
helpers, as for any git command the user runs.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

EMPTY_TREE = "4b825dc642cb6eb9a060e54bf8d69288fbee4904"
# user:password@ (or token@) in URLs that git or the forge echo back.
_URL_CREDENTIALS = re.compile(r"(?P<scheme>[a-zA-Z][a-zA-Z0-9+.-]*://)(?P<user>[^/@\s:]*)(?::[^/@\s]*)?@")
# Environment variables whose values are secrets wherever they appear.
SECRET_VARIABLES = ("GITHUB_TOKEN", "GH_TOKEN", "MPC_GITHUB_TOKEN", "GITLAB_TOKEN", "CI_JOB_TOKEN",
                    "SYSTEM_ACCESSTOKEN")


class DeployError(Exception):
    """A deployment step failed; `code` and the (scrubbed) message become a diagnostic."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(scrub(message))
        self.code = code
        self.message = scrub(message)


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
    repository (`.gitmodules`) or to compare clones by, since CI tokens change from job to job."""
    def keep_ssh_user(m: re.Match[str]) -> str:
        # ssh://git@host/x names the account, not a secret; any password goes all the same
        ssh = "ssh" in m.group("scheme").lower()
        return m.group("scheme") + (f"{m.group('user')}@" if ssh and m.group("user") else "")

    return _URL_CREDENTIALS.sub(keep_ssh_user, url)


def git_environment() -> dict[str, str]:
    """Variables for every git run: never prompt (a CI job has nobody to answer)."""
    return {"GIT_TERMINAL_PROMPT": "0", "LC_ALL": "C"}


class Git:
    """git in one folder; `git("status", "--porcelain")` → output without the final newline."""

    def __init__(self, folder: Path) -> None:
        import git

        self.folder = folder
        self._git = git.Git(str(folder))
        # Never look for a repository above `folder`: should its .git be missing, git must
        # fail rather than work on a repository around the workdir (the definitions', say).
        self._git.update_environment(**git_environment(), GIT_CEILING_DIRECTORIES=str(folder.parent))

    def __call__(self, *args: str, code: str = "E0803", check: bool = True) -> str:
        import git

        _check_arguments(args, code)
        try:
            return self._git.execute(["git", *args], with_extended_output=False, strip_newline_in_stdout=True)
        except git.GitCommandError as e:
            if not check:
                return ""
            stderr = (e.stderr or "").strip().removeprefix("stderr:").strip().strip("'").strip()
            raise DeployError(code, f"git {args[0]} failed in '{self.folder}': {stderr or e}") from None

    def ok(self, *args: str) -> bool:
        """Whether the git command succeeds (for questions such as `rev-parse --verify`)."""
        import git

        try:
            self._git.execute(["git", *args])
            return True
        except git.GitCommandError:
            return False

    def result(self, *args: str) -> tuple[int, str, str]:
        """(status, stdout, stderr) of a git command that may fail (push)."""
        _check_arguments(args, "E0803")
        status, out, err = self._git.execute(["git", *args], with_extended_output=True,
                                             with_exceptions=False)
        return status, out, err


def _check_arguments(args: tuple[str, ...], code: str) -> None:
    """A NUL byte cannot be passed to a program (a protocol or title from YAML may hold one)."""
    for arg in args:
        if "\0" in arg:
            raise DeployError(code, f"git {args[0]} cannot take an argument with a NUL byte "
                                    f"(at offset {arg.index(chr(0))} of '{arg[:40]}…')")
