"""Running git in one repository, with credentials kept out of messages.

`Git(folder)` runs `git <args>` there through mpc's one git runner (core/gitrun.py:
never prompting, credentials scrubbed) and returns its output; a failure raises
`DeployError` with git's own message.
"""

from __future__ import annotations

from pathlib import Path

from mpc.core import gitrun
from mpc.core.gitrun import SECRET_VARIABLES, git_environment, scrub, without_credentials

__all__ = ["EMPTY_TREE", "SECRET_VARIABLES", "DeployError", "Git", "git_environment", "scrub",
           "without_credentials"]

EMPTY_TREE = "4b825dc642cb6eb9a060e54bf8d69288fbee4904"


class DeployError(Exception):
    """A deployment step failed; `code` and the (scrubbed) message become a diagnostic."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(scrub(message))
        self.code = code
        self.message = scrub(message)


class Git:
    """git in one folder; `git("status", "--porcelain")` → output without the final newline."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        # Never look for a repository above `folder`: should its .git be missing, git must
        # fail rather than work on a repository around the workdir (the definitions', say).
        self._env = {"GIT_CEILING_DIRECTORIES": str(folder.parent)}

    def __call__(self, *args: str, code: str = "E0803", check: bool = True) -> str:
        _check_arguments(args, code)
        try:
            return gitrun.git(*args, cwd=self.folder, env=self._env)
        except gitrun.GitFailed as e:
            if not check:
                return ""
            raise DeployError(code, f"git {args[0]} failed in '{self.folder}': "
                                    f"{e.stderr.strip() or e.message}") from None
        except OSError as e:  # the folder is gone, git is missing
            raise DeployError(code, f"git {args[0]} cannot run in '{self.folder}': {e.strerror}") from None

    def ok(self, *args: str) -> bool:
        """Whether the git command succeeds (for questions such as `rev-parse --verify`)."""
        try:
            return gitrun.result(args, self.folder, self._env)[0] == 0
        except OSError:
            return False

    def result(self, *args: str) -> tuple[int, str, str]:
        """(status, stdout, stderr) of a git command that may fail (push)."""
        _check_arguments(args, "E0803")
        return gitrun.result(args, self.folder, self._env)


def _check_arguments(args: tuple[str, ...], code: str) -> None:
    """A NUL byte cannot be passed to a program (a protocol or title from YAML may hold one)."""
    for arg in args:
        if "\0" in arg:
            raise DeployError(code, f"git {args[0]} cannot take an argument with a NUL byte "
                                    f"(at offset {arg.index(chr(0))} of '{arg[:40]}…')")
