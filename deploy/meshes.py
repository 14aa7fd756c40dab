"""Central mesh repositories (`central_meshes`, as Phobos has them): the build's
`meshes/<type>/` goes to the repository `remote_base` + `meshes[type]`, and the model
repository gets it as a submodule at `meshes/<type>`, pinned to the commit just pushed.

A mesh repository pools the meshes of every model of the pipeline, so a deployment adds
and updates files there but deletes none. Types without an entry in `meshes` stay inside
the model repository.
"""

from __future__ import annotations

from pathlib import Path, PurePosixPath

from mpc.deploy import content, lfs
from mpc.deploy.gitcmd import DeployError, without_credentials
from mpc.deploy.plan import Plan, lfs_patterns
from mpc.deploy.repository import Clone, folder_for, locked, open_clone, publish
from mpc.deploy.settings import DeploySettings, join_remote
from mpc.deploy.submodules import Pinned


def deploy_meshes(built: Path, modelname: str, settings: DeploySettings, plan: Plan, message: str,
                  workdir: Path) -> list[Pinned]:
    """Push each central mesh folder of the build; the submodules that link them."""
    pins = []
    branch = settings.mesh_branch or plan.base
    for mesh_type, path in sorted(settings.meshes.items()):
        if not _plain_name(mesh_type):
            raise DeployError("E0801", f"central mesh type '{mesh_type}' of the pipeline's meshes is not a "
                                       "folder name of the build's meshes/")
        source = built / "meshes" / mesh_type
        if not source.is_dir():
            continue
        if not settings.remote_base:
            raise DeployError("E0802", "central_meshes needs the pipeline's remote_base to find the "
                                       "mesh repositories")
        url = join_remote(settings.remote_base, path)
        folder = folder_for(workdir / ".meshes", url)
        with locked(folder):
            pin = _deploy_one(source, url, folder, mesh_type, path, branch, settings, plan,
                              f"[mpc] Meshes ({mesh_type}) of {modelname}\n{_body(message)}")
        if pin is not None:
            pins.append(pin)
    return pins


def _plain_name(name: str) -> bool:
    return bool(name) and not name.startswith(".") and "/" not in name and "\\" not in name


def _body(message: str) -> str:
    return message.split("\n", 1)[1] if "\n" in message else ""


def _deploy_one(source: Path, url: str, folder: Path, mesh_type: str, path: str, branch: str,
                settings: DeploySettings, plan: Plan, message: str) -> Pinned | None:
    """Push one mesh folder; the submodule that links it (None: nothing to link yet)."""
    clone = open_clone(url, folder, settings.remote_name)
    uses_lfs = settings.uses_lfs or PurePosixPath(path).name.startswith("lfs")
    patterns = lfs_patterns(plan.lfs_patterns, uses_lfs) if uses_lfs else ()

    def fill(c: Clone) -> None:
        for rel in content.build_entries(source):
            content.copy_entry(source, rel, content.safe_path(c.folder, rel))
        lfs.track(c.git, patterns)
        c.git("add", "-A")

    published = publish(clone, branch, None, fill, message, settings.dry_run)
    sha = published.sha or clone.remote_sha(branch)
    if sha is None:  # a dry run against an empty mesh repository: nothing to link yet
        return None
    return Pinned(f"meshes/{mesh_type}", without_credentials(url), url, branch, sha, clone.folder)
