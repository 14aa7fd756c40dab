"""A robot's mesh files → W0505 for each that holds no triangle, naming it and the links
that use it; it changes nothing.

A mesh without triangles draws nothing and collides with nothing, and a consumer may refuse
it (MuJoCo does). Copied meshes are not read to write them, so the test is a cheap look at
the file by its format: a binary STL's triangle count, a whole ASCII STL's or an OBJ's faces, a
COLLADA file's primitive index lists (`<p>`). Formats it cannot tell cheaply are not judged;
a mesh that cannot be read is left to the mesh export (E0602, E0603).
"""

from __future__ import annotations

import os
import re
import struct
from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.robot import Robot

_DAE_INDICES = re.compile(rb"<p[\s>]")  # an index list of <triangles>, <polylist> or <polygons>
_OBJ_FACE = re.compile(rb"^\s*f\s", re.MULTILINE)


def binary_stl_triangles(path: Path) -> int | None:
    """The triangle count of a binary STL, read from its header (the rest is not read); None
    when the file is not a binary STL whose count fits its size. Raises OSError."""
    with open(path, "rb") as f:
        head, size = f.read(84), os.fstat(f.fileno()).st_size
    if len(head) == 84 and size == 84 + 50 * struct.unpack_from("<I", head, 80)[0]:
        return int(struct.unpack_from("<I", head, 80)[0])
    return None


def has_no_triangles(path: Path) -> bool:
    """Whether the mesh file at `path` surely holds no triangle; False when unsure. What a whole
    file was read for is remembered with its digest (core/cache.py): a warm build reads none."""
    from mpc.core.cache import remembered

    suffix = path.suffix.lower()
    try:
        if suffix == ".stl" and (count := binary_stl_triangles(path)) is not None:
            return count == 0
        if suffix not in (".stl", ".obj", ".dae"):
            return False
        verdict = remembered(path, "no triangles", lambda f: "1" if _none_in(suffix, f.read()) else "0", 1)
        return verdict == "1"
    except OSError:
        return False


def _none_in(suffix: str, data: bytes) -> bool:
    """Whether the bytes of a whole mesh file in the format of `suffix` hold no triangle."""
    if suffix == ".stl":
        # ASCII: whole (it ends) but without a facet; a file that is neither is left to reading it
        return data.lstrip().startswith(b"solid") and b"endsolid" in data and b"facet" not in data
    if suffix == ".obj":
        return _OBJ_FACE.search(data) is None
    return _DAE_INDICES.search(data) is None


def check_empty(robot: Robot, sink: Sink, span: Span) -> None:
    """Warn (W0505) once for each mesh file of the robot without triangles, at its first use,
    naming the file and each link (and element) that uses it."""
    from mpc.backends.meshes import mesh_uses

    users: dict[Path, list[str]] = {}
    first: dict[Path, Span] = {}
    for use in mesh_uses(robot):
        path = use.mesh.source.path
        if path is None:
            continue
        users.setdefault(path, [])
        first.setdefault(path, use.mesh.span or span)
        where = f"the {use.element} of link '{use.link}'"
        if where not in users[path]:
            users[path].append(where)
    for path, where in users.items():
        if has_no_triangles(path):
            sink.warning(first[path], "W0505", f"mesh file '{path}' has no triangles; it is used by "
                         f"{', '.join(where)}", hint="it draws nothing and collides with nothing: "
                         "export the mesh again, or remove the element")
