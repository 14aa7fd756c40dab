"""Meshes of a robot → files in the output folder, with unique, stable names.

Each mesh goes to `meshes/<format>/<basename>`, the extension in lower case. Two
different files with the same basename are told apart by a content hash in their
names; the same file used twice is written once. Converting between formats is not
done here yet: a mesh whose format differs from the export's is a diagnostic.
"""

from __future__ import annotations

import filecmp
import hashlib
import shutil
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from mpc.compiler.diagnostics import Sink
from mpc.ir.geometry import Mesh
from mpc.ir.robot import Robot
from mpc.ir.span import Span
from mpc.ir.tree import depth_first

KEEP_FORMAT = "input_type"


@dataclass(frozen=True, slots=True)
class MeshUse:
    """A mesh and where the robot uses it: link name and element kind."""

    link: str
    element: str
    mesh: Mesh


def mesh_uses(robot: Robot) -> Iterator[MeshUse]:
    """Every mesh of the robot in canonical order (depth-first, visuals then collisions)."""
    for _, name in depth_first(robot):
        link = robot.links[name]
        for kind, items in (("visual", link.visuals), ("collision", link.collisions)):
            for item in items:
                if isinstance(item.geometry, Mesh):
                    yield MeshUse(name, kind, item.geometry)


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:10]


def plan(robot: Robot, mesh_format: str, sink: Sink, export_span: Span) -> dict[Path, str] | None:
    """Map each mesh file to its path in the output (relative, `meshes/<fmt>/<name>`).

    Reports meshes that cannot be found or would need a conversion; None if any.
    """
    ok = True
    wanted: dict[Path, str] = {}
    conversions: dict[str, MeshUse] = {}
    for use in mesh_uses(robot):
        src = use.mesh.source
        span = use.mesh.span or export_span
        if src.path is None:
            sink.error(span, "E0602", f"mesh '{src.uri}' of a {use.element} of link '{use.link}' "
                       f"cannot be found: {src.unresolved}",
                       hint="map the package with --package NAME=DIR or ROS_PACKAGE_PATH")
            ok = False
            continue
        if src.path in wanted:
            continue
        if not src.path.is_file():
            sink.error(span, "E0602", f"mesh file '{src.path}' of a {use.element} of link "
                       f"'{use.link}' does not exist")
            ok = False
            continue
        fmt = src.format if mesh_format == KEEP_FORMAT else mesh_format
        if fmt != src.format:
            conversions.setdefault(src.format, use)
            continue
        stem = src.path.name.rsplit(".", 1)[0]
        wanted[src.path] = f"meshes/{fmt}/{stem}.{fmt}"
    for fmt, use in sorted(conversions.items()):
        sink.error(export_span, "E0501", f"converting '{fmt}' meshes to '{mesh_format}' is not "
                   f"supported yet (first: '{use.mesh.source.uri}' of link '{use.link}')",
                   notes=((use.mesh.span, "the mesh is used here"),),
                   hint="use `mesh_format: input_type` to keep each mesh's own format")
        ok = False
    if not ok:
        return None
    return _disambiguate(wanted)


def _disambiguate(wanted: dict[Path, str]) -> dict[Path, str]:
    by_name: dict[str, list[Path]] = {}
    for path, name in wanted.items():
        by_name.setdefault(name, []).append(path)
    out = dict(wanted)
    for name, paths in by_name.items():
        if len(paths) == 1:
            continue
        first = paths[0]
        if all(filecmp.cmp(first, p, shallow=False) for p in paths[1:]):
            continue
        stem, ext = name.rsplit(".", 1)
        for p in paths:
            out[p] = f"{stem}_{_digest(p)}.{ext}"
    return out


def copy(files: dict[Path, str], out: Path) -> None:
    """Copy each planned mesh file into `out` (content only, no metadata)."""
    for src, rel in sorted(files.items(), key=lambda kv: kv[1]):
        dest = out / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        if not dest.exists():
            shutil.copyfile(src, dest)
