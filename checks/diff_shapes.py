"""The visuals and collisions of one link in two models → their changes.

Shapes pair by position in the link (the readers keep the file's order). A shape changed
when its kind, its size (beyond `distance`), its placement (beyond `distance` or `rad`) or
its mesh's content changed; a collision's volume is said beside it, a visual mesh's faces
and bytes. A mesh file is read only when its content differs from the other side's (by
digest, checks/pictures.py), so an unchanged model reads none.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from mpc.checks.diff_change import Change
from mpc.checks.pictures import mesh_digest, turned
from mpc.ir.geometry import Box, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.program import Tolerances
from mpc.ir.robot import Link, Material


def describe(g: Geometry) -> str:
    """A shape in a few words: `box 0.1×0.2×0.3`, `mesh leg.stl`."""
    match g:
        case Box():
            return "box " + "×".join(f"{x:.4g}" for x in g.size)
        case Cylinder():
            return f"cylinder r {g.radius:.4g} l {g.length:.4g}"
        case Sphere():
            return f"sphere r {g.radius:.4g}"
        case Mesh():
            scale = "" if g.scale in (None, (1.0, 1.0, 1.0)) else " scaled " + "×".join(
                f"{x:.4g}" for x in g.scale or ())
            return f"mesh {Path(g.source.uri).name}{scale}"
    return type(g).__name__.lower()


def _sizes(g: Geometry) -> tuple[float, ...]:
    match g:
        case Box():
            return tuple(g.size)
        case Cylinder():
            return (g.radius, g.length)
        case Sphere():
            return (g.radius,)
        case Mesh():
            return tuple(g.scale or (1.0, 1.0, 1.0))
    return ()


def mesh_facts(g: Geometry) -> dict[str, Any]:
    """A mesh's faces, bytes and volume (m³, its solid: ir/solids.py), as far as they can be
    read; a primitive's volume."""
    from mpc.ir.mesh_props import MeshError, as_trimesh, solid

    facts: dict[str, Any] = {}
    if isinstance(g, Mesh):
        path = g.source.path
        if path is not None and Path(path).is_file():
            facts["bytes"] = Path(path).stat().st_size
        try:
            facts["faces"] = len(as_trimesh(g).faces)
        except MeshError:
            return facts
    with contextlib.suppress(MeshError, ValueError):  # a volume only where there is one
        facts["volume"] = float(solid(g).props.mass)
    return facts


def _content_changed(a: Geometry, b: Geometry) -> bool:
    return isinstance(a, Mesh) and isinstance(b, Mesh) and mesh_digest(a) != mesh_digest(b)


def shape_change(a: Any, b: Any, tol: Tolerances) -> list[str]:
    """What changed between two visuals or two collisions, in words (empty: nothing)."""
    ga, gb = a.geometry, b.geometry
    out = []
    other_file = isinstance(ga, Mesh) and isinstance(gb, Mesh) and \
        Path(ga.source.uri).name != Path(gb.source.uri).name and _content_changed(ga, gb)
    if type(ga) is not type(gb) or other_file or \
            np.max(np.abs(np.subtract(_sizes(ga), _sizes(gb))), initial=0.0) > tol.distance:
        out.append(f"{describe(ga)} → {describe(gb)}")
    elif _content_changed(ga, gb):
        out.append(f"{describe(gb)}: its content changed")
    d, angle = turned(a.origin, b.origin)
    if d > tol.distance or angle > tol.rad:
        out.append(f"moved by {d:.4g} m, turned by {angle:.4g} rad")
    return out


def _facts_text(kind: str, before: dict[str, Any], after: dict[str, Any]) -> str:
    parts = []
    for key, unit in (("faces", "faces"), ("bytes", "bytes"), ("volume", "m³")):
        if kind == "visuals" and key == "volume":
            continue
        if key in before or key in after:
            x, y = before.get(key), after.get(key)
            if x != y:
                fmt = "{:.4g}" if key == "volume" else "{}"
                parts.append(f"{fmt.format(x) if x is not None else '?'} → "
                             f"{fmt.format(y) if y is not None else '?'} {unit}")
    return ", ".join(parts)


def link_shapes(old: Link, new: Link, tol: Tolerances, old_materials: Mapping[str, Material],
                new_materials: Mapping[str, Material]) -> Iterator[Change]:
    """The changes of the link's visuals and collisions; a visual's material is compared by
    its colour where it has one (formats differ in naming materials), else by name."""
    for kind, element in (("collisions", "collision"), ("visuals", "visual")):
        a, b = getattr(old, kind), getattr(new, kind)
        for i in range(max(len(a), len(b))):
            what = f"{element} {i}"
            if i >= len(a):
                facts = mesh_facts(b[i].geometry) if kind == "collisions" else {}
                volume = f" (volume {facts['volume']:.4g} m³)" if "volume" in facts else ""
                yield Change(element, new.name, "added", None, describe(b[i].geometry),
                             f"{what} added: {describe(b[i].geometry)}{volume}")
                continue
            if i >= len(b):
                yield Change(element, new.name, "removed", describe(a[i].geometry), None,
                             f"{what} removed: {describe(a[i].geometry)}")
                continue
            said = shape_change(a[i], b[i], tol)
            if said:
                facts_a, facts_b = mesh_facts(a[i].geometry), mesh_facts(b[i].geometry)
                facts = _facts_text(kind, facts_a, facts_b)
                yield Change(element, new.name, "shape", {"shape": describe(a[i].geometry), **facts_a},
                             {"shape": describe(b[i].geometry), **facts_b},
                             f"{what}: {'; '.join(said)}" + (f" ({facts})" if facts else ""))
            if kind != "visuals":
                continue
            ma, mb = _material(a[i], old_materials), _material(b[i], new_materials)
            if ma != mb:
                yield Change("visual", new.name, "material", ma, mb, f"{what}: material {ma} → {mb}")


def _material(visual: Any, materials: Mapping[str, Material]) -> str:
    m = visual.inline_material or (materials.get(visual.material) if visual.material else None)
    if m is not None and m.rgba is not None:
        return "rgba " + " ".join(f"{x:.3g}" for x in m.rgba)
    return str(visual.material) if visual.material else "none"
