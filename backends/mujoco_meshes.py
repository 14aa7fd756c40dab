"""Which mesh files MuJoCo reads as they are: the rules of its STL and OBJ decoders, for the
meshes an MJCF export writes (backends/meshes.py).

MuJoCo reads a mesh file through a decoder of its own (plugin/stl_decoder, plugin/obj_decoder
on tinyobjloader), stricter than trimesh and than the URDF consumers that read the same files:
- an STL must be binary, exactly 84 + 50 × n bytes, with 1 to 200,000 triangles, each
  coordinate finite and within ±2^30. An ASCII STL (common in ROS packages) or one with bytes
  after its triangles is refused: such a file is written again as a binary STL.
- an OBJ gives MuJoCo its first object only (tinyobjloader's first shape: the faces up to the
  first `o` or `g` that more faces follow): an OBJ of several objects is written again as one,
  as is a face line that tinyobjloader cannot read but trimesh can (a comment after the
  indices, a line continued with `\\`) and a file with normals that some face corner does not
  name (MuJoCo then takes the corner's normal from outside the list and refuses the file). A
  face that names no vertex (`f 2 x`, index 0, an index beyond the vertices) or a coordinate
  that is not finite is refused by both readers, or read as another shape by trimesh: such a
  file is not written.

Of any mesh, MuJoCo wants 4 vertices or more (an STL's equal vertices counted once) and
triangles of some area (1e-15 m² in all): a mesh of one triangle, or of triangles with no area,
is refused. A collision mesh has more rules: MuJoCo computes its convex hull (a visual's it
does not), and refuses one whose vertices lie in one plane or on one line ("coplanar vertices,
cannot compute convex hull"), and one of an OBJ file with a coordinate far out (qhull fails on
a box with a corner at 1e20, and so MuJoCo; an STL's coordinates are bounded by ±2^30 already):
beyond ±2^30, a collision mesh is refused.

`verdict` says which of the three a file is, remembered by the file's status (core/cache.py);
`problem` says why a refused file is refused. RULES names these rules in what is remembered.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

RULES = "mujoco 2"  # changes when the rules change, so that no verdict of older ones is used
READS = "0"  # MuJoCo reads the file as it is
REWRITE = "1"  # the same mesh, written again, is one MuJoCo reads
REFUSED = "2"  # the file is refused (`problem` says why)

MAX_STL_TRIANGLES = 200_000  # plugin/stl_decoder/stl_decoder.cc
BOUND = 2.0**30  # the same: the largest coordinate it reads
MIN_VERTICES = 4  # the same: "at least 4 vertices required"
MIN_AREA = 1e-15  # src/user/user_mesh.cc (mjMINVAL): the least surface of a mesh it reads
SIZE_HINT = ("reduce the mesh (`reduce_meshes`) or write OBJ meshes (`mesh_format: obj`), which have no "
             "such limit")
REPAIR_HINT = "export the mesh again from its modelling tool"
FLAT_HINT = ("give the link a primitive collision instead (`collisions: {<link>: {shape: box}}`), "
             "as MuJoCo suggests")
# Vertices whose spread across their thinnest direction is below this fraction of their widest
# spread lie in one plane for MuJoCo, which computes the hull in single precision.
_FLAT = 1e-6

_VERTEX_LINE = re.compile(rb"^[ \t]*v[ \t]", re.MULTILINE)
_NORMAL_LINE = re.compile(rb"^[ \t]*vn[ \t]", re.MULTILINE)
_LEADING_INT = re.compile(rb"[+-]?\d+")


def verdict(path: Path, collision: bool = False) -> str:
    """READS, REWRITE or REFUSED for the mesh file `path` (STL or OBJ; other files READS) of a
    visual, or of a `collision`; remembered by its status; raises OSError when it cannot be
    read."""
    from mpc.core.cache import remembered

    suffix = path.suffix.lower()
    if suffix not in (".stl", ".obj"):
        return READS
    what = f"{RULES} collision" if collision else RULES
    return remembered(path, what, lambda f: judge(f.read(), suffix, collision)[0], 1)


def problem(path: Path, collision: bool = False) -> tuple[str, str]:
    """Why MuJoCo refuses the mesh file `path`, and what to do (a file `verdict` refuses)."""
    return judge(path.read_bytes(), path.suffix.lower(), collision)[1:]


def judge(data: bytes, suffix: str, collision: bool = False) -> tuple[str, str, str]:
    """(verdict, why refused, hint) for a mesh file's bytes, of a visual or of a `collision`."""
    import numpy as np

    verdict, why, hint, triangles, vertices = _stl(data) if suffix == ".stl" else _obj(data)
    if verdict != READS:
        return verdict, why, hint
    if vertices < MIN_VERTICES:
        return (REFUSED, f"it has {vertices} vertices; MuJoCo reads a mesh of {MIN_VERTICES} or more",
                REPAIR_HINT)
    corners = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                axis=1).sum()
    if not area >= MIN_AREA:
        return (REFUSED, f"its triangles have no area ({area:.3g} m² in all; MuJoCo refuses a mesh of "
                f"less than {MIN_AREA:g})", REPAIR_HINT)
    far = (np.abs(corners) > BOUND).any(axis=(1, 2)) if collision else np.zeros(0, dtype=bool)
    if far.any():
        return (REFUSED, f"triangle {int(far.argmax()) + 1} has a coordinate beyond ±2^30, where MuJoCo "
                "cannot compute the convex hull of a collision mesh", REPAIR_HINT)
    if collision and _flat(corners.reshape(-1, 3)):
        return (REFUSED, "its vertices lie in one plane, and MuJoCo computes the convex hull of a "
                "collision mesh", FLAT_HINT)
    return verdict, why, hint


def _flat(points: Any) -> bool:
    """Whether the points lie in one plane (or on one line), as MuJoCo's hull finds them."""
    import numpy as np

    centred = points - points.mean(axis=0)
    size = np.abs(centred).max()
    if not size > 0:
        return True
    centred = centred / size  # of any size: the squares below stay finite
    moments = np.linalg.eigvalsh(centred.T @ centred)  # the squared spreads, least first
    return bool(moments[0] <= _FLAT**2 * moments[2])


# verdict, why, hint, the triangles' corners ((n, 3, 3)), the vertices as MuJoCo counts them
Judged = tuple[str, str, str, Any, int]


def _stl(data: bytes) -> Judged:
    import numpy as np

    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else 0
    if count < 1 or len(data) != 84 + 50 * count:
        return REWRITE, "", "", (), 0  # ASCII, or binary of another length: MuJoCo reads neither
    if count > MAX_STL_TRIANGLES:
        return (REFUSED, f"it has {count:,} triangles; MuJoCo reads at most {MAX_STL_TRIANGLES:,} "
                "from an STL file", SIZE_HINT, (), 0)
    record = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
    vertices = np.frombuffer(data, record, offset=84)["vertices"].reshape(count, 9)
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        why = f"triangle {int(bad.argmax()) + 1} has a coordinate that is not finite"
        return REFUSED, why, REPAIR_HINT, (), 0
    far = (np.abs(vertices) > BOUND).any(axis=1)
    if far.any():
        return (REFUSED, f"triangle {int(far.argmax()) + 1} has a coordinate beyond ±2^30, the largest "
                "MuJoCo reads", REPAIR_HINT, (), 0)
    return READS, "", "", vertices, _distinct(vertices.reshape(-1, 3))  # MuJoCo merges equal ones


def _distinct(points: Any) -> int:
    """How many different points there are, as far as MIN_VERTICES asks: those of the first 64
    when they hold enough (sorting a large mesh's points to count them all took most of a
    check's time)."""
    import numpy as np

    def count(some: Any) -> int:
        return len(np.unique(np.ascontiguousarray(some).view(np.dtype((np.void, some.itemsize * 3)))))

    first = count(points[:64])
    return first if first >= MIN_VERTICES or len(points) <= 64 else count(points)


def _obj(data: bytes) -> Judged:
    """The OBJ rules of the module's docstring, one line at a time."""
    total, with_normals = len(_VERTEX_LINE.findall(data)), _NORMAL_LINE.search(data) is not None
    vertices = normals = objects = 0  # vertices and normals so far; objects (tinyobjloader's
    # shapes) with faces so far
    faces_here = rewrite = False
    points: list[tuple[float, float, float]] = []
    triangles: list[tuple[int, int, int]] = []  # as tinyobjloader makes them of each face
    for number, raw in enumerate(data.split(b"\n"), 1):
        words = raw.split()
        if not words:
            continue
        word = words[0]
        if raw.rstrip().endswith(b"\\"):
            rewrite = True  # tinyobjloader does not join continued lines
        if word == b"v":
            vertices += 1
            point = [0.0, 0.0, 0.0]
            for axis, text in enumerate(words[1:4]):
                try:
                    point[axis] = float(text)
                except ValueError:
                    continue  # read as 0 by tinyobjloader (trimesh reports it)
                if not math.isfinite(point[axis]):
                    return (REFUSED, f"vertex {vertices} has a coordinate that is not finite "
                            f"('{_shown(text)}', line {number})", REPAIR_HINT, (), 0)
            points.append((point[0], point[1], point[2]))
        elif word == b"vn":
            normals += 1
        elif word == b"f":
            if not faces_here:
                faces_here, objects = True, objects + 1
            face: list[int] = []
            for corner in words[1:]:
                if corner.startswith(b"#"):
                    rewrite = True  # a comment: tinyobjloader reads it as a corner
                    break
                why = _corner_problem(corner, vertices, total)
                if why:
                    return REFUSED, f"{why} (line {number})", REPAIR_HINT, (), 0
                if with_normals and not _names_a_normal(corner, normals):
                    rewrite = True
                index = int(_LEADING_INT.match(corner)[0])  # type: ignore[index]  # checked above
                face.append(index - 1 if index > 0 else vertices + index)
            triangles += [(face[0], face[k], face[k + 1]) for k in range(1, len(face) - 1)]
        elif word in (b"o", b"g"):
            faces_here = False
    if rewrite or objects > 1:
        return REWRITE, "", "", (), 0
    return READS, "", "", [[points[i] for i in triangle] for triangle in triangles], vertices


def _corner_problem(corner: bytes, before: int, total: int) -> str:
    """Why a face's corner (`v`, `v/vt`, `v//vn` or `v/vt/vn`) names no vertex, or ""; `before`:
    the vertices above its line, `total`: the file's."""
    parts = corner.split(b"/")
    if len(parts) > 3:
        return f"a face corner '{_shown(corner)}' is not v, v/vt, v//vn or v/vt/vn"
    found = _LEADING_INT.match(parts[0])  # tinyobjloader reads the leading digits, as atoi does
    if found is None:
        return f"a face corner '{_shown(corner)}' names no vertex"
    digits = found[0].lstrip(b"+-")
    if not digits.strip(b"0"):
        return f"a face corner '{_shown(corner)}' names vertex 0 (an OBJ counts its vertices from 1)"
    magnitude = _magnitude(digits)
    if found[0][:1] != b"-" and magnitude > total:
        return f"a face corner '{_shown(corner)}' names vertex {_shown(digits)} of the file's {total}"
    if found[0][:1] == b"-" and magnitude > before:
        return f"a face corner '{_shown(corner)}' counts back beyond the {before} vertices above it"
    return ""


def _magnitude(digits: bytes) -> int:
    """The number the digits write, or 10^18 for more than 18 of them (more than any file has
    vertices; Python refuses to read past 4,300 digits as an int)."""
    return int(digits) if len(digits) <= 18 else 10**18


def _names_a_normal(corner: bytes, before: int) -> bool:
    """Whether the face corner (`v//vn`, `v/vt/vn`) names one of the `before` normals above it."""
    parts = corner.split(b"/")
    found = _LEADING_INT.match(parts[2]) if len(parts) == 3 else None
    return found is not None and 0 < _magnitude(found[0].lstrip(b"+-")) <= before


def _shown(text: bytes) -> str:
    """A word of the file as a diagnostic quotes it: printable, and at most 40 characters."""
    shown = text.decode("utf-8", "replace")
    shown = "".join(c if c.isprintable() else "?" for c in shown)
    return shown if len(shown) <= 40 else shown[:37] + "..."
