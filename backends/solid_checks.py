"""A robot's collision meshes → W0582, once per mesh, for each closed mesh that a mesh op
(reduce_meshes, convex_decomposition, apply_scale by a zero factor) left open; it changes
nothing.

A reflection (mirror) or a scale by non-zero factors keeps a closed mesh closed: the same
triangles, their winding reversed where the mesh is reflected (tests/backends/
test_solid_meshes.py measures it on TALOS's meshes). They are not read again for it, which
would double the cost of a cold mirrored build. Each mesh value that needs it is checked
once per content (its file's bytes and its ops): the answer is kept in the cache
(core/cache.py: `solids/`), so a rebuild does not compute it again.
"""

from __future__ import annotations

import hashlib
import json
import os

from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.geometry import ConvexPart, JoinShapes, Mesh, MeshOp, ReduceMesh, ScaleMesh
from mpc.ir.robot import Robot

VERSION = "1"  # changes when the test for closed changes, so old answers go unused
WATCHED = {ScaleMesh: "apply_scale", ReduceMesh: "reduce_meshes", ConvexPart: "convex_decomposition"}


def _may_open(op: MeshOp) -> bool:
    return type(op) in WATCHED and not (isinstance(op, ScaleMesh) and all(op.scale))


def check_closed(robot: Robot, sink: Sink, span: Span) -> None:
    """Warn (W0582) once for each mesh that was closed and is not after one of its ops,
    naming the links whose collisions use it and the op. Only a collision serves as a solid
    (volumes, centres, inertias, `join: union`): a visual that comes apart only looks so.
    Unreadable meshes are left to the mesh export (E0602)."""
    from mpc.backends.meshes import mesh_uses

    users: dict[tuple[object, object], tuple[Mesh, list[str]]] = {}
    for use in mesh_uses(robot):
        mesh = use.mesh
        joined = bool(mesh.ops) and isinstance(mesh.ops[0], JoinShapes)  # made of parts: no file to read
        if use.element != "collision" or joined or not any(_may_open(op) for op in mesh.ops):
            continue
        if mesh.source.path is None or not mesh.source.path.is_file():
            continue
        links = users.setdefault((mesh.source.path, mesh.ops), (mesh, []))[1]
        if use.link not in links:
            links.append(use.link)
    for mesh, links in users.values():
        opened = opened_by(mesh)
        if opened is None:
            continue
        named = f"link '{links[0]}'" if len(links) == 1 else \
            "links " + ", ".join(f"'{link}'" for link in links[:3]) + (f" and {len(links) - 3} more"
                                                                      if len(links) > 3 else "")
        sink.warning(mesh.span or span, "W0582", f"mesh '{mesh.source.uri}' of a collision of {named} "
                     f"is a closed solid but not after {opened}",
                     hint="volumes and inertias from it use its convex hull; try a gentler reduction")


def opened_by(mesh: Mesh) -> str | None:
    """The op (its language key) after which the closed mesh is no longer closed, else None."""
    assert mesh.source.path is not None
    h = hashlib.sha256(mesh.source.path.read_bytes())
    h.update(f"{VERSION}|{mesh.ops!r}".encode())
    from mpc.core.cache import cache_dir

    path = cache_dir("solids") / f"{h.hexdigest()}.json"
    try:
        return json.loads(path.read_text())["opened_by"]
    except (OSError, ValueError, KeyError, TypeError):
        pass  # not there yet, or unreadable: compute it again
    answer = _opened_by(mesh)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.{os.getpid()}.part")
    partial.write_text(json.dumps({"opened_by": answer}))
    os.replace(partial, path)
    return answer


def _opened_by(mesh: Mesh) -> str | None:
    from mpc.ir.mesh_props import MeshError, as_trimesh
    from mpc.ir.solids import closed

    try:
        if not closed(as_trimesh(Mesh(source=mesh.source), scaled=False)):
            return None
        for n, op in enumerate(mesh.ops):
            if _may_open(op) and not closed(as_trimesh(Mesh(source=mesh.source, ops=mesh.ops[:n + 1]),
                                                             scaled=False)):
                return WATCHED[type(op)]
    except MeshError:
        return None
    return None
