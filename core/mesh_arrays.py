"""Mesh files ↔ numpy arrays without trimesh, pycollada or SciPy: the common conversions.

STL (binary and ASCII) and COLLADA (.dae) decode into vertices and triangles; a transform
(a reflection, a scale) applies to them; STL and OBJ encode them. Each step computes what
trimesh 5 computes for `trimesh.load(path, force="mesh", process=False)`, `apply_transform`
and `export`, with the same numpy operations in the same order, so that the bytes written are
the same (tests/backends/test_mesh_arrays.py compares them on every example-robot-data mesh).

A decoder returns None for what it does not reproduce exactly (a DAE with textures,
controllers, instanced nodes or references that do not resolve, an STL of several solids,
a mesh whose numbers are not finite): the caller then takes the trimesh path, which also
says why a broken file is refused. Imports numpy and lxml only.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import replace
from typing import Any

import numpy as np

from mpc.core.record import record

TOL_ZERO = float(np.finfo(np.float64).resolution * 100)  # trimesh's: a degenerate triangle's normal is 0
TRIMESH_HEADER = "# https://github.com/mikedh/trimesh"  # the first line of every OBJ mpc has written


@record(slots=True)
class Arrays:
    """A triangle mesh: (n, 3) float64 vertices and (m, 3) int64 triangles."""

    vertices: np.ndarray
    faces: np.ndarray


def decode(data: bytes, suffix: str) -> Arrays | None:
    """The mesh of a file's bytes by its suffix (`.stl`, `.dae`, any case), or None when this
    module does not reproduce trimesh's reading of it."""
    suffix = suffix.lower()
    try:
        if suffix == ".stl":
            arrays = decode_stl(data)
        elif suffix == ".dae":
            arrays = decode_dae(data)
        else:
            return None
    except (ValueError, TypeError, KeyError, IndexError, SyntaxError, RecursionError):  # XMLSyntaxError too
        return None
    return arrays if arrays is not None and _sound(arrays) else None


def _sound(arrays: Arrays) -> bool:
    """Whether the mesh has triangles, finite vertices and indices within them (otherwise the
    trimesh path reads it, to refuse it with its reason)."""
    v, f = arrays.vertices, arrays.faces
    return (v.ndim == 2 and v.shape[1] == 3 and f.ndim == 2 and f.shape[1] == 3 and len(f) > 0
            and bool(np.isfinite(v).all()) and int(f.min()) >= 0 and int(f.max()) < len(v))


# ---- STL

_STL_RECORD = np.dtype([("normals", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])


def decode_stl(data: bytes) -> Arrays | None:
    """Binary when the header's triangle count matches the file's length, else ASCII."""
    count = _stl_count(data)
    if count is not None:
        if count == 0:
            return None
        blob = np.frombuffer(data, dtype=_STL_RECORD, offset=84)
        vertices = blob["vertices"].reshape((-1, 3)).astype(np.float64)
        return Arrays(vertices, np.arange(count * 3, dtype=np.int64).reshape((-1, 3)))
    return _decode_stl_ascii(data)


def _stl_count(data: bytes) -> int | None:
    """A binary STL's triangle count: its header's, when the file's length agrees; else None."""
    if len(data) < 84:
        return None
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
    return count if len(data) - 84 == count * _STL_RECORD.itemsize else None


def _decode_stl_ascii(data: bytes) -> Arrays | None:
    """One `solid … endsolid` of vertex lines (several solids: None)."""
    text = data.decode("utf-8", errors="replace").strip().lower()
    start, end = text.find("solid"), text.find("endsolid")
    if start < 0 or end < 0 or start > end or text.find("endsolid", end + 8) >= 0:
        return None
    chunks = text[start:end].split("vertex")[1:]
    values = np.array(" ".join(c[: c.find("\n")] for c in chunks).split(), dtype=np.float64)
    if len(values) < 9 or len(values) % 9:
        return None
    vertices = values.reshape((-1, 3))
    return Arrays(vertices, np.arange(len(vertices), dtype=np.int64).reshape((-1, 3)))


def obj_name(data: bytes, file_name: str) -> str | None:
    """The name trimesh gives the object of an STL file: a binary file's own name, an ASCII
    file's solid's name (None when it has none: not reproduced here)."""
    if _stl_count(data) is not None:
        return file_name
    text = data.decode("utf-8", errors="replace").strip()
    start = text.lower().find("solid")
    if start < 0:
        return None
    line = text[start:].split("\n", 1)[0]
    name = line[6:].strip()
    return name or None


def face_normals(triangles: np.ndarray) -> np.ndarray:
    """The unit normal of each triangle (its corners: `vertices[faces]`), 0 for a degenerate
    one (trimesh's `face_normals`)."""
    vectors = triangles[:, 1:, :] - triangles[:, :2, :]
    crosses = np.cross(vectors[:, 0], vectors[:, 1])
    norm = np.sqrt(np.dot(crosses * crosses, [1.0] * 3))
    valid = norm > TOL_ZERO
    norm[valid] **= -1
    unit = crosses * norm.reshape((-1, 1))
    normals = np.zeros((len(triangles), 3), dtype=np.float64)
    normals[valid] = unit[valid]
    return normals


def encode_stl(arrays: Arrays) -> bytes:
    """A binary STL: an empty 80-byte header, the count, each triangle's normal and corners."""
    header = bytes(80) + np.array([len(arrays.faces)], dtype="<u4").tobytes()
    packed = np.zeros(len(arrays.faces), dtype=_STL_RECORD)
    triangles = arrays.vertices[arrays.faces]
    packed["normals"] = face_normals(triangles)
    packed["vertices"] = triangles
    return header + packed.tobytes()


def encode_obj(arrays: Arrays, name: str) -> bytes:
    """An OBJ of one object `name`: its vertices (8 decimals) and triangles (1-based)."""
    vertices = "\nv ".join(" ".join(f"{x:.8f}" for x in row) for row in arrays.vertices.tolist())
    faces = "\nf ".join(f"{a} {b} {c}" for a, b, c in (arrays.faces + 1).tolist())
    body = "\n".join((f"\no {name}", f"v {vertices}", f"f {faces}"))
    return "\n".join((TRIMESH_HEADER, body, "\n")).encode()


# ---- transforms

_IDENTITY4 = np.eye(4)


def transform(arrays: Arrays, matrix: np.ndarray) -> Arrays:
    """The mesh moved by a homogeneous 4×4 matrix; a reflection reverses each triangle's
    winding (trimesh's `apply_transform`: the same products, so the same rounding)."""
    matrix = np.asarray(matrix, dtype=np.float64)
    if np.abs(matrix - _IDENTITY4).max() < 1e-8:
        return arrays
    points = arrays.vertices
    vertices = np.dot(matrix, np.column_stack((points, np.ones(len(points)))).T).T[:, :3]
    faces = arrays.faces
    has_rotation = not np.abs(matrix[:3, :3] - _IDENTITY4[:3, :3]).max() < 1e-6
    if has_rotation and np.linalg.det(matrix[:3, :3]) < 0.0:
        faces = np.ascontiguousarray(np.fliplr(faces))
    return replace(arrays, vertices=np.ascontiguousarray(vertices), faces=faces)


def scale_matrix(factors: Any) -> np.ndarray:
    """trimesh's `apply_scale` matrix for a number or three numbers (each scales a column)."""
    matrix = np.eye(4)
    if np.any(np.asarray(factors) != 1):
        matrix[:3, :3] *= factors
    return matrix


def concatenate(parts: list[Arrays]) -> Arrays:
    """The meshes as one: vertices in order, each part's triangles offset by those before it."""
    offsets = np.cumsum([0] + [len(p.vertices) for p in parts[:-1]])
    return Arrays(np.vstack([p.vertices for p in parts]),
                  np.vstack([p.faces + o for p, o in zip(parts, offsets, strict=True)]))


# ---- COLLADA

_UNIT = re.compile(rb"<unit\b[^>]*\bmeter=\"([0-9.eE+-]+)\"")
# What pycollada reads into more than triangles, or reads differently: its presence sends the
# file down the trimesh path.
_UNHANDLED = re.compile(rb"<(?:\w+:)?(?:texture|instance_controller|instance_node|lookat|skew|ph|"
                        rb"tristrips|trifans)\b")


def unit(data: bytes) -> float:
    """Metres per unit of a COLLADA file (its <unit meter=…>), 1 when it has none."""
    m = _UNIT.search(data[:4096])
    return float(m.group(1)) if m else 1.0


def decode_dae(data: bytes) -> Arrays | None:
    """The triangles of every geometry the scene instances, in document order, moved by their
    nodes' transforms and scaled to metres, as pycollada and trimesh's loader give them."""
    if _UNHANDLED.search(data):
        return None
    import lxml.etree

    from mpc.core.span import hardened_parser

    root = lxml.etree.fromstring(data, hardened_parser(huge=True))
    ns = root.tag[: root.tag.index("}") + 1] if root.tag.startswith("{") else ""
    ids = {e.get("id"): e for e in root.iter(f"{ns}geometry", f"{ns}visual_scene", f"{ns}material",
                                              f"{ns}effect") if e.get("id") is not None}
    instance = root.find(f"{ns}scene/{ns}instance_visual_scene")
    scene = None if instance is None else ids.get((instance.get("url") or "").removeprefix("#"))
    if scene is None or scene.tag != f"{ns}visual_scene":
        return None
    parts: list[Arrays] = []
    for node in scene.iterfind(f"{ns}node"):
        if not _walk(node, np.eye(4), ns, ids, parts):
            return None
    if not parts:
        return None
    mesh = concatenate(parts)
    return transform(mesh, scale_matrix(unit(data)))


def _walk(node: Any, parent: np.ndarray, ns: str, ids: dict[str, Any], parts: list[Arrays]) -> bool:
    """Add the geometry under `node` to `parts`; False for what is not reproduced."""
    transforms = [_transform(child, ns) for child in node
                  if child.tag in (f"{ns}matrix", f"{ns}translate", f"{ns}rotate", f"{ns}scale")]
    if any(t is None for t in transforms):
        return False
    if not transforms:
        local = np.identity(4, dtype=np.float32)
    elif len(transforms) == 1 and transforms[0] is not None:
        local = transforms[0].copy()
    else:
        local = np.identity(4, dtype=np.float32)
        for t in transforms:
            if t is not None:  # none is (above); for the type checker
                local = np.dot(local, t)
    for child in node:
        if child.tag == f"{ns}node":
            if not _walk(child, np.dot(parent, local), ns, ids, parts):
                return False
        elif child.tag == f"{ns}instance_geometry":
            geometry = ids.get((child.get("url") or "").removeprefix("#"))
            if geometry is None or geometry.tag != f"{ns}geometry" or not _materials_resolve(child, ns, ids):
                return False
            bound = {str(m.get("symbol")) for m in child.iter(f"{ns}instance_material")}
            found = _geometry(geometry, ns, bound)
            if found is None:
                return False
            placed = _repaired(np.asarray(np.dot(parent, local), dtype=np.float64))
            parts.extend(transform(p, placed) for p in found)
    return True


def _repaired(matrix: np.ndarray) -> np.ndarray:
    """A node's placement as trimesh's scene graph gives it: a rotation that is nearly one
    (off by more than 1e-13 and less than 1e-5) made one, through its SVD."""
    check = np.abs(np.dot(matrix[:3, :3], matrix[:3, :3].T) - _IDENTITY4[:3, :3]).max()
    if 1e-13 < check < 1e-5:
        u, _, v = np.linalg.svd(matrix[:3, :3])
        repaired = np.eye(4)
        repaired[:3, :3] = np.dot(u, v)
        repaired[:3, 3] = matrix[:3, 3]
        return repaired
    return matrix


def _transform(element: Any, ns: str) -> np.ndarray | None:
    """A node's transform element as pycollada computes it (float32)."""
    values = _numbers(element.text, np.float32)
    tag = element.tag[len(ns):]
    if tag == "matrix":
        return values.reshape((4, 4)) if len(values) == 16 else None
    if tag == "translate" and len(values) == 3:
        matrix = np.identity(4, dtype=np.float32)
        matrix[:3, 3] = values
        return matrix
    if tag == "scale" and len(values) == 3:
        matrix = np.identity(4, dtype=np.float32)
        matrix[0, 0], matrix[1, 1], matrix[2, 2] = values
        return matrix
    if tag == "rotate" and len(values) == 4:
        x, y, z, angle = values
        angle = angle * np.pi / 180.0
        c, s = np.cos(angle), np.sin(angle)
        t = 1 - c
        return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0],
                         [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0],
                         [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0],
                         [0, 0, 0, 1]], dtype=np.float32)
    return None


def _materials_resolve(instance: Any, ns: str, ids: dict[str, Any]) -> bool:
    """Whether each material the geometry binds, and its effect, exist (pycollada drops the
    geometry of a node whose binding is broken: mpc reads that file its own way)."""
    for bound in instance.iter(f"{ns}instance_material"):
        material = ids.get((bound.get("target") or "").removeprefix("#"))
        if material is None or material.tag != f"{ns}material":
            return False
        effect = material.find(f"{ns}instance_effect")
        if effect is None or ids.get((effect.get("url") or "").removeprefix("#")) is None:
            return False
    return True


def _geometry(geometry: Any, ns: str, bound: set[str]) -> list[Arrays] | None:
    """One mesh per triangle primitive of a geometry (lines are no triangles), its corners
    merged as trimesh merges a loaded geometry's vertices (`_merged`). bound: the material
    symbols its instance binds (a primitive with a bound material keeps its texture
    coordinates, which keep corners apart)."""
    mesh = geometry.find(f"{ns}mesh")
    if mesh is None:
        return None
    sources: dict[str, Any] = {s.get("id"): s for s in mesh.iterfind(f"{ns}source")}
    vertices = mesh.find(f"{ns}vertices")
    shared = [] if vertices is None else [
        ("VERTEX" if i.get("semantic") == "POSITION" else i.get("semantic"), i.get("source") or "")
        for i in vertices.iterfind(f"{ns}input")]
    parts: list[Arrays] = []
    parsed: dict[tuple[str, int], np.ndarray | None] = {}
    movables: dict[str, np.ndarray] = {}
    for primitive in mesh:
        tag = primitive.tag[len(ns):] if isinstance(primitive.tag, str) else ""
        if tag not in ("triangles", "polylist", "polygons"):
            continue
        inputs: dict[str, list[tuple[int, str]]] = {}  # semantic → (offset, source), in pycollada's order
        for given in primitive.iterfind(f"{ns}input"):
            offset = int(given.get("offset", "0"))
            if given.get("semantic") == "VERTEX":
                for semantic, source in shared:
                    inputs.setdefault(str(semantic), []).append((offset, source))
            else:
                inputs.setdefault(str(given.get("semantic")), []).append((offset, given.get("source") or ""))
        stride = 1 + max((offset for found in inputs.values() for offset, _ in found), default=0)
        rows = _corner_rows(primitive, tag, ns, stride)
        if rows is None:
            return None
        if "VERTEX" not in inputs or not len(rows):
            continue  # no vertices: trimesh skips the primitive
        position = _indexed(sources, inputs["VERTEX"][0], rows, ns, 3, parsed)
        normals = _indexed(sources, inputs["NORMAL"][0], rows, ns, 3, parsed) if "NORMAL" in inputs else None
        uv = None
        if "TEXCOORD" in inputs and primitive.get("material") in bound:
            uv = _indexed(sources, inputs["TEXCOORD"][0], rows, ns, 2, parsed)
            if uv is None:
                return None
        if position is None or ("NORMAL" in inputs and normals is None):
            return None
        source = inputs["VERTEX"][0][1]
        if source not in movables:  # judged on the source's values: fewer than the corners
            movables[source] = _movable(position[0].astype(np.float64))
        merged = _merged(position, normals, uv, movables[source][position[1]])
        parts.append(Arrays(merged, np.arange(len(merged), dtype=np.int64).reshape((-1, 3))))
    return parts


def _corner_rows(primitive: Any, tag: str, ns: str, stride: int) -> np.ndarray | None:
    """The primitive's corners as rows of indices (one per input offset), three a triangle
    (a polygon fanned from its first corner); None when the counts do not add up."""
    if tag == "polygons":
        polygons = [_ints(p.text) for p in primitive.iterfind(f"{ns}p")]
        index = np.concatenate(polygons) if polygons else np.zeros(0, dtype=np.int64)
        counts: np.ndarray | None = np.array([len(p) // stride for p in polygons], dtype=np.int64)
    else:
        p = primitive.find(f"{ns}p")
        index = _ints(None if p is None else p.text)
        counts = None
        if tag == "polylist":
            vcount = primitive.find(f"{ns}vcount")
            counts = _ints(None if vcount is None else vcount.text)
    if len(index) % stride:
        return None
    rows = index.reshape((-1, stride))
    if counts is not None:
        if int(counts.sum()) != len(rows) or (len(counts) and int(counts.min()) < 3):
            return None
        return rows[_fan(np.arange(len(rows)), counts)]
    return rows if len(rows) % 3 == 0 else None


Indexed = tuple[np.ndarray, np.ndarray]  # a source's values (float32) and their index at each corner


def _indexed(sources: dict[str, Any], given: tuple[int, str], rows: np.ndarray, ns: str, width: int,
             parsed: dict[tuple[str, int], np.ndarray | None]) -> Indexed | None:
    """An input's values and their index at each corner, or None (a source missing or out of
    range). parsed: the geometry's sources parsed so far (each is parsed once)."""
    offset, source = given
    key = (source, width)
    if key not in parsed:
        parsed[key] = _float_source(sources.get(source.removeprefix("#")), ns, width)
    values = parsed[key]
    if values is None:
        return None
    index = rows[:, offset]
    if int(index.min()) < 0 or int(index.max()) >= len(values):
        return None
    return values, index


def _merged(position: Indexed, normals: Indexed | None, uv: Indexed | None,
            movable: np.ndarray) -> np.ndarray:
    """The corners' points (float64), each moved to the first corner that trimesh merges it
    with: the same position to 8 decimals, texture coordinate to 4 and normal to 2
    (`Trimesh.merge_vertices`, which trimesh's COLLADA loader does). Only the corners
    `movable` marks can move (`_movable`); the others are left as they are."""
    points = position[0][position[1]].astype(np.float64)
    movable = np.nonzero(movable)[0]
    if not len(movable):
        return points
    stacked = [points[movable] * (10**8)]
    for given, scale in ((uv, 10**4), (normals, 10**2)):
        if given is not None:
            stacked.append(given[0][given[1][movable]].astype(np.float64) * scale)
    keys = np.column_stack(stacked).round().astype(np.int64)
    order = np.lexsort(keys.T[::-1])  # stable: the first of equal keys is the first corner
    ordered = keys[order]
    starts = np.empty(len(keys), dtype=bool)
    starts[:1] = True
    starts[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    first = np.empty(len(keys), dtype=np.int64)
    first[order] = order[starts][np.cumsum(starts) - 1]
    points[movable] = points[movable[first]]  # the right side is a copy
    return points


def _movable(points: np.ndarray) -> np.ndarray:
    """The points with a coordinate that rounds to 8 decimals as another, different value of
    its column does (0 and -0 among them). Corners merge only when all their coordinates round
    alike, so a corner at a point without one merges with none but its equals, and those it
    merges with have one too."""
    movable = np.zeros(len(points), dtype=bool)
    for column in points.T:
        values, inverse = np.unique(column, return_inverse=True)
        keys = (values * (10**8)).round()
        same = keys[1:] == keys[:-1]
        shared = np.zeros(len(values), dtype=bool)
        shared[1:] |= same
        shared[:-1] |= same
        movable |= shared[inverse.reshape(-1)]
        zeros = column == 0
        if zeros.any():
            signs = np.signbit(column[zeros])
            if signs.any() and not signs.all():
                movable |= zeros
    return movable


def _ints(text: str | None) -> np.ndarray:
    return _numbers(text, np.int64)


def _numbers(text: str | None, dtype: type) -> np.ndarray:
    """The whitespace-separated numbers of an element's text, parsed as pycollada parses them
    (numpy's own parser); ValueError for text that is not all numbers."""
    if not text or text.isspace():
        return np.zeros(0, dtype=dtype)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns, and stops, at a word that is no number
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (DeprecationWarning, RuntimeWarning) as e:
            raise ValueError(str(e)) from None


def _fan(corners: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Polygons of `counts` corners as triangles fanned from each first corner."""
    starts = np.cumsum(counts) - counts
    triangles = counts - 2
    first = np.repeat(starts, triangles)
    step = np.arange(int(triangles.sum())) - np.repeat(np.cumsum(triangles) - triangles, triangles)
    fanned = np.stack([corners[first], corners[first + step + 1], corners[first + step + 2]], axis=1)
    return fanned.reshape(-1)


def _float_source(source: Any, ns: str, width: int) -> np.ndarray | None:
    """A <source>'s float array as pycollada reads it (float32, nan made 0), a row of `width`
    params each."""
    if source is None:
        return None
    array = source.find(f"{ns}float_array")
    accessor = source.find(f"{ns}technique_common/{ns}accessor")
    if array is None or accessor is None:
        return None
    params = accessor.findall(f"{ns}param")
    if len(params) != width or int(accessor.get("stride", str(width))) != width:
        return None
    values = _numbers(array.text, np.float32)
    if len(values) % width:
        return None
    values[np.isnan(values)] = 0
    return values.reshape((-1, width))
