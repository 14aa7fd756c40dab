"""DAE readers on every DAE file of example-robot-data: time, and whether they give the same triangles.

1. before issue 19: pycollada twice (once for the broken references, once inside trimesh.load);
2. mpc's reader (core/collada.py): pycollada once, turned into a mesh as trimesh's loader does;
3. a direct lxml + numpy reader of `<triangles>`/`<polylist>` with the `<unit>` and the `<node>`
   transforms (written here only to be measured).

A reader is correct when it gives the triangles of (1), vertex for vertex (within 1e-9 m; the
order of the triangles may differ). mpc keeps (2): (3) gives the triangles but not what
trimesh adds that the OBJ export writes (merged vertices, texture coordinates, names), so
it would change outputs. Run: python bench/bench_dae.py [--limit N]
"""

from __future__ import annotations

import argparse
import io
import re
import time
from pathlib import Path

import numpy as np
import trimesh
from lxml import etree

from mpc.core import collada
from mpc.core.packages import PackageResolver
from mpc.core.span import hardened_parser


def before(path: Path) -> trimesh.Trimesh:
    """The reader before issue 19 (core/collada.py at 7fb6e0b)."""
    import collada as pycollada

    data = path.read_bytes()
    ignore = [pycollada.common.DaeBrokenRefError, pycollada.common.DaeUnsupportedError]
    if pycollada.Collada(io.BytesIO(data), ignore=ignore).errors:
        data = collada._without_material_bindings(data)
    mesh = trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)
    mesh.apply_scale(collada._unit(data))
    return mesh


def _matrix(node: etree._Element) -> np.ndarray:
    M = np.eye(4)
    for t in node:
        tag = etree.QName(t).localname
        values = np.array(t.text.split(), dtype=float) if t.text else np.zeros(0)
        if tag == "matrix":
            M = M @ values.reshape(4, 4)
        elif tag == "translate":
            T = np.eye(4)
            T[:3, 3] = values
            M = M @ T
        elif tag == "scale":
            M = M @ np.diag([*values, 1.0])
        elif tag == "rotate":
            M = M @ trimesh.transformations.rotation_matrix(np.radians(values[3]), values[:3])
    return M


def direct(path: Path) -> np.ndarray:
    """Triangles (n, 3, 3) in metres, straight from the XML."""
    root = etree.fromstring(path.read_bytes(), hardened_parser(huge=True))
    unit = root.find("{*}asset/{*}unit")
    scale = float(unit.get("meter", 1.0)) if unit is not None else 1.0
    floats = {}  # float32, as pycollada reads them
    for s in root.iter("{*}source"):
        if s.find("{*}float_array") is not None:
            stride = int(s.find("{*}technique_common/{*}accessor").get("stride", 3))
            values = np.array(s.findtext("{*}float_array").split(), dtype=np.float32).astype(float)
            floats[s.get("id")] = values.reshape(-1, stride)[:, :3]
    positions = {v.get("id"): floats[v.find("{*}input[@semantic='POSITION']").get("source")[1:]]
                 for v in root.iter("{*}vertices")}
    geometries: dict[str, list[np.ndarray]] = {}
    for g in root.iter("{*}geometry"):
        parts = []
        for prim in g.iterfind("{*}mesh/*"):
            kind = etree.QName(prim).localname
            if kind not in ("triangles", "polylist") or prim.find("{*}p") is None:
                continue
            inputs = prim.findall("{*}input")
            stride = max(int(i.get("offset", 0)) for i in inputs) + 1
            vertex = next(i for i in inputs if i.get("semantic") == "VERTEX")
            p = np.array(prim.findtext("{*}p").split(), dtype=np.int64).reshape(-1, stride)
            index = p[:, int(vertex.get("offset", 0))]
            if kind == "polylist":
                counts = np.array(prim.findtext("{*}vcount").split(), dtype=np.int64)
                starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
                fans = [np.stack([np.full(c - 2, s), s + np.arange(1, c - 1), s + np.arange(2, c)], axis=1)
                        for s, c in zip(starts, counts, strict=True) if c >= 3]
                index = index[np.concatenate(fans).reshape(-1)] if fans else index[:0]
            parts.append(positions[vertex.get("source")[1:]][index.reshape(-1, 3)])
        geometries[g.get("id")] = parts
    out: list[np.ndarray] = []
    nodes = {n.get("id"): n for n in root.iter("{*}node")}

    def walk(node: etree._Element, M: np.ndarray) -> None:
        M = M @ _matrix(node)
        for instance in node.iterfind("{*}instance_geometry"):
            for tri in geometries.get(instance.get("url")[1:], []):
                out.append(tri @ M[:3, :3].T + M[:3, 3])
        for instance in node.iterfind("{*}instance_node"):
            walk(nodes[instance.get("url")[1:]], M)
        for child in node.iterfind("{*}node"):
            walk(child, M)

    scene = root.find("{*}scene/{*}instance_visual_scene")
    visual = next(v for v in root.iter("{*}visual_scene") if v.get("id") == scene.get("url")[1:])
    for node in visual.iterfind("{*}node"):
        walk(node, np.eye(4))
    return np.concatenate(out) * scale if out else np.zeros((0, 3, 3))


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """The same triangles (n, 3, 3), with the same orientation, in any order and starting at any
    corner, within 1e-9."""
    if a.shape != b.shape:
        return False

    def canonical(t: np.ndarray) -> np.ndarray:
        rounded = np.round(t, 6)
        turns = np.stack([np.roll(rounded, -k, axis=1).reshape(len(t), 9) for k in range(3)], axis=1)
        first = np.array([min(range(3), key=lambda k: tuple(row[k])) for row in turns])
        t = np.stack([np.roll(tri, -k, axis=0) for tri, k in zip(t, first, strict=True)])
        return t[np.lexsort(np.round(t.reshape(len(t), 9), 6).T[::-1])]

    return bool(np.allclose(canonical(a), canonical(b), atol=1e-9, rtol=0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, help="only the first N files (by size, smallest first)")
    args = parser.parse_args()
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "pip install example-robot-data"
    files = sorted((p for p in (erd / "robots").rglob("*") if re.search(r"\.dae$", p.name, re.I)),
                   key=lambda p: p.stat().st_size)[:args.limit]
    seconds = {"before": 0.0, "mpc": 0.0, "direct": 0.0}
    agree = {"mpc": 0, "direct": 0}
    for path in files:
        t = time.perf_counter()
        try:
            reference: np.ndarray | None = before(path).triangles
        except Exception:
            reference = None
        seconds["before"] += time.perf_counter() - t
        for name, read in (("mpc", lambda p: collada.read(p)[0].triangles), ("direct", direct)):
            t = time.perf_counter()
            try:
                found: np.ndarray | None = read(path)
            except Exception:
                found = None
            seconds[name] += time.perf_counter() - t
            ok = found is None if reference is None else found is not None and same(reference, found)
            agree[name] += ok
    size = sum(p.stat().st_size for p in files) / 2**20
    print(f"{len(files)} DAE files of example-robot-data ({size:.0f} MiB)")
    for name, s in seconds.items():
        extra = f", same triangles for {agree[name]} of {len(files)}" if name in agree else ""
        print(f"  {name:7s} {s:7.2f} s ({s / seconds['before']:.2f} of before){extra}")


if __name__ == "__main__":
    main()
