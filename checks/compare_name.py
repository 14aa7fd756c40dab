"""A compare model → how the test protocol names it, without the runner's paths.

The protocol ends up in a merge request, read by people who do not have the runner's
folders: a folder or a local repository is named relative to the definition's folder, as
long as it lies in the project (the git work tree holding the definition, else its folder);
one outside the project by its name alone. A remote repository is named by its address
without credentials.
"""

from __future__ import annotations

import os
from pathlib import Path

from mpc.core.files import project_root
from mpc.ir.program import CompareTarget


def is_local(git: str) -> bool:
    """Whether a compare model's `git` is a folder on disk (after lowering: an absolute path),
    not an address (`scheme://…` or scp-like `user@host:path`)."""
    return "://" not in git and "@" not in git.split("/")[0] and Path(git).is_absolute()


def shown_path(path: Path, definition: Path) -> str:
    """`path` relative to the definition's folder when it lies in the project, else
    `<name> (outside the project)`."""
    path = path.resolve()
    if path.is_relative_to(project_root(definition.resolve().parent)):
        return Path(os.path.relpath(path, definition.resolve().parent)).as_posix()
    return f"{path.name} (outside the project)"


def compare_name(target: CompareTarget, definition: Path | None) -> str:
    """What the protocol calls the compare model (see the module's docstring)."""
    from mpc.core.gitrun import without_credentials

    if target.git and not is_local(target.git):
        return without_credentials(target.git)
    where = Path(target.git) if target.git else target.path
    assert where is not None
    if definition is None:
        return where.name
    return shown_path(where, definition)
