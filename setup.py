"""mpc's packages, derived from the folders: `mpc.NAME` is the top-level folder NAME.

The design keeps the floors (core/, ir/, backends/, ...) at the repository's root, and they
install as `mpc.*`. setuptools cannot prefix the packages it finds, so this file finds them:
every top-level folder with an `__init__.py` except tests/ is a floor, and every folder under
a floor that holds a Python file is a subpackage. A new folder lands in the wheel without an
edit here (tests/test_packaging.py builds the wheel and checks). Everything else about the
project is in pyproject.toml.

scripts/setup.sh also loads this file (without running setuptools) for `link_tree`, the
`mpc` folder of links that editors and type checkers follow in a checkout.
"""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent
NOT_MPC = frozenset({"tests"})  # top-level packages that are not part of mpc


def floors(root: Path = ROOT) -> list[str]:
    """The top-level folders that install as `mpc.NAME`, sorted."""
    return sorted(
        entry.name
        for entry in root.iterdir()
        if entry.is_dir() and entry.name.isidentifier() and entry.name not in NOT_MPC
        and (entry / "__init__.py").is_file()
    )


def package_dirs(root: Path = ROOT) -> dict[str, str]:
    """Every package of mpc (`mpc.ir.ops`) → its folder relative to `root` (`ir/ops`)."""
    out = {}
    for floor in floors(root):
        for folder, dirs, files in os.walk(root / floor):
            dirs[:] = sorted(d for d in dirs if d.isidentifier() and d != "__pycache__")
            if any(f.endswith(".py") for f in files):
                relative = Path(folder).relative_to(root)
                out[".".join(("mpc", *relative.parts))] = relative.as_posix()
    return out


def link_tree(target: Path, root: Path = ROOT) -> None:
    """Make `target/mpc/NAME` a link to each floor, and drop links to floors that are gone.

    With `target` on sys.path (a .pth file), `import mpc.ir` finds the checkout's ir/ through
    a plain folder, which static tools (basedpyright, jedi) follow, unlike setuptools' import
    hook of an editable install.
    """
    top = target / "mpc"
    top.mkdir(parents=True, exist_ok=True)
    wanted = set(floors(root))
    for entry in top.iterdir():
        if entry.is_symlink() and entry.name not in wanted:
            entry.unlink()
    for name in sorted(wanted):
        link = top / name
        if link.is_symlink() and link.resolve() == (root / name).resolve():
            continue
        if link.is_symlink():
            link.unlink()
        link.symlink_to(root / name, target_is_directory=True)


if __name__ == "__main__":
    from setuptools import setup

    dirs = package_dirs()
    setup(packages=sorted(dirs), package_dir=dirs)
