"""A clone's working tree ← the build: everything is replaced except `.git`, the kept files
and the submodule folders; README.md (and manifest.xml) are written when missing.

It touches nothing outside the clone, follows no symbolic link out of it, and copies the
build's dotfiles too (Phobos's `git add -A *` never committed them, §5 step 9).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from mpc.deploy.gitcmd import DeployError

# What a build may hold but never goes into a repository: git's own metadata. A `.git`
# (folder, or file naming one) at any depth would turn its folder into an embedded repository;
# `.gitmodules` is mpc's to write, from `deployment.submodules`.
_GIT_METADATA = ".git"
_GITMODULES = ".gitmodules"


def kept_files(clone: Path, patterns: tuple[str, ...]) -> set[str]:
    """Files of the clone that a `keep_files` glob names (a folder keeps what is inside it);
    paths relative to the clone, with `/`. Nothing behind a symbolic link is looked at."""
    kept: set[str] = set()
    for pattern in patterns:
        for match in clone.glob(pattern):
            rel = match.relative_to(clone)
            if _GIT_METADATA in rel.parts or _behind_link(clone, rel.parent):
                continue
            if match.is_dir() and not match.is_symlink():
                kept.update(p.relative_to(clone).as_posix() for p in match.rglob("*")
                            if not p.is_dir() or p.is_symlink())
            else:
                kept.add(rel.as_posix())
    return kept


def not_deployed(built: Path) -> list[str]:
    """The git metadata in a build, which is left out of the repository (W0840)."""
    return [rel for rel in _entries(built, set()) if _is_git_metadata(rel)]


def build_entries(built: Path, skip: frozenset[str] | set[str] = frozenset()) -> list[str]:
    """What of the build goes into a repository: its files and links, without git metadata."""
    return [rel for rel in _entries(built, skip) if not _is_git_metadata(rel)]


def _is_git_metadata(rel: str) -> bool:
    return _GIT_METADATA in rel.split("/") or rel == _GITMODULES


def _entries(folder: Path, skip: frozenset[str] | set[str]) -> list[str]:
    """Files, symbolic links and `.git` folders under `folder` (relative, with `/`, sorted),
    entering neither the `skip` folders, nor symbolic links, nor `.git` folders."""
    out = []
    for top, dirs, files in os.walk(folder):
        rel_top = Path(top).relative_to(folder)
        for d in list(dirs):
            rel = (rel_top / d).as_posix()
            if rel in skip:
                dirs.remove(d)
            elif d == _GIT_METADATA or (Path(top) / d).is_symlink():
                dirs.remove(d)
                out.append(rel)
        out.extend((rel_top / f).as_posix() for f in files)
    return sorted(out)


def safe_path(clone: Path, rel: str) -> Path:
    """`clone / rel`, once no folder on the way is a symbolic link (which could lead out of the
    clone: its content comes from the remote); E0804 otherwise."""
    if _behind_link(clone, Path(rel).parent) or not _inside((clone / rel).parent, clone):
        raise DeployError("E0804", f"'{rel}' would be written outside the repository (through a "
                                   "symbolic link in it)")
    return clone / rel


def _behind_link(clone: Path, rel: Path) -> bool:
    path = clone
    for part in rel.parts:
        path = path / part
        if path.is_symlink():
            return True
    return False


def replace_content(clone: Path, built: Path, keep: set[str], skip: set[str]) -> None:
    """Empty the clone but for `.git`, `keep` and the `skip` folders; copy the build into it
    (without what lies in `skip`, and without overwriting kept files)."""
    for rel in _entries(clone, skip):
        if rel not in keep and rel != _GIT_METADATA:
            (clone / rel).unlink()
    for top, dirs, _ in os.walk(clone, topdown=False):
        rel_top = Path(top).relative_to(clone).as_posix()
        if rel_top != "." and rel_top.split("/")[0] != _GIT_METADATA and rel_top not in skip \
                and not any(rel_top.startswith(s + "/") for s in skip) and not dirs and not os.listdir(top):
            os.rmdir(top)
    for rel in build_entries(built, skip):
        if rel in keep or any(rel.startswith(s + "/") for s in skip):
            continue
        copy_entry(built, rel, safe_path(clone, rel))


def copy_entry(built: Path, rel: str, target: Path) -> None:
    """One file or symbolic link of the build to `target`. A link stays a link (relative, when
    the build has it absolute); one that leads out of the build is E0844, since copying what it
    names could publish any file of the machine."""
    source = built / rel
    target.parent.mkdir(parents=True, exist_ok=True)
    if not source.is_symlink():
        shutil.copy2(source, target)
        return
    link = os.readlink(source)
    named = source.parent / link
    if not _inside(named, built):
        raise DeployError("E0844", f"the build's '{rel}' is a symbolic link to '{link}', outside the "
                                   "build; mpc deploys no file from outside the build")
    if os.path.isabs(link):
        link = os.path.relpath(named.resolve(), source.parent.resolve())
    os.symlink(link, target)


def _inside(path: Path, folder: Path) -> bool:
    return path.resolve().is_relative_to(folder.resolve())


README = """# {modelname}

The robot model `{robotname}`, built by mpc (the model pipeline compiler) from its
model definition{definition}.

This repository is written by the pipeline: change the model definition rather than the
files here; files listed under `keep_files` in the definition are kept.
{mention}{lfs}"""

LFS_NOTE = """
## Git LFS

The meshes are stored with [Git LFS](https://git-lfs.com): install it (`apt-get install
git-lfs`, then `git lfs install`) before cloning, or run `git lfs pull` after.
"""


def write_readme(clone: Path, modelname: str, robotname: str, definition: str | None,
                 mention: tuple[str, ...], lfs: bool) -> bool:
    """README.md from the template when the clone has none; whether it was written."""
    path = clone / "README.md"
    if path.exists() or path.is_symlink():
        return False
    path.write_text(README.format(
        modelname=modelname, robotname=robotname,
        definition=f" `{definition}`" if definition else "",
        mention=f"\nMaintainers: {', '.join(mention)}\n" if mention else "",
        lfs=LFS_NOTE if lfs else ""), encoding="utf-8")
    return True


MANIFEST = """<package>
  <description brief="{modelname}">The robot model {robotname}, generated by mpc.</description>
  <license>{license}</license>
{maintainers}</package>
"""


def write_manifest(clone: Path, modelname: str, robotname: str, mention: tuple[str, ...]) -> bool:
    """An autoproj manifest.xml when the clone has none (no maintainer URL is made up)."""
    from mpc.backends.xml_escape import text as escape

    path = clone / "manifest.xml"
    if path.exists() or path.is_symlink():
        return False
    maintainers = "".join(f"  <maintainer>{escape(m)}</maintainer>\n" for m in mention)
    path.write_text(MANIFEST.format(modelname=escape(modelname), robotname=escape(robotname),
                                    license="see the model definition", maintainers=maintainers),
                    encoding="utf-8")
    return True
