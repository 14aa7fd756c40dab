"""The mesh conversions that need no trimesh: STL or DAE → STL, STL → OBJ, with reflections and
scales (core/mesh_arrays.py); each source decoded once for all the outputs made from it.

`plain` says which cache jobs this path takes; `derive` writes their cache entries, or says
that the file is one the path does not reproduce (the caller then computes every job of that
source with trimesh, backends/meshes.py `_derive`, as before). The bytes are those the
trimesh path writes (tests/backends/test_mesh_arrays.py). numpy is imported only to derive:
a build whose meshes are all in the cache loads none of it.
"""

from __future__ import annotations

from pathlib import Path

from mpc.ir.geometry import MeshOp
from mpc.ir.mesh_plain import applied, is_plain

_OUTPUTS = {".stl": (".stl",), ".dae": (".stl",)}  # source suffix → what this path writes of it
_OBJ_SOURCES = (".stl",)  # an OBJ names its object; known here for an STL


def plain(src: Path, ops: tuple[MeshOp, ...], suffix: str) -> bool:
    """Whether the cache entry of `src` with `ops`, written as `suffix`, is this path's."""
    kind = src.suffix.lower()
    if not src.is_absolute() or kind not in _OUTPUTS:
        return False
    if suffix not in _OUTPUTS[kind] and not (suffix == ".obj" and kind in _OBJ_SOURCES):
        return False
    return is_plain(ops)


Job = tuple[Path, tuple[MeshOp, ...], Path]  # source, ops, cache entry (backends/meshes.py)


def materialise(jobs: list[Job]) -> dict[Path, tuple[str, str]] | None:
    """Make the cache entries of the jobs of one source; {entry: (code, problem)} for those
    that failed, or None when the file is not one this path reproduces. Done once across
    processes: one that finds the first entry locked waits, then makes only what is missing."""
    from mpc.core.cache import load_entry, single_flight, store_entry, trace
    from mpc.core.files import describe

    src = jobs[0][0]
    try:
        with single_flight(jobs[0][2]):
            missing = [(ops, dest) for _, ops, dest in jobs if load_entry(dest)[0] is None]
            if not missing:
                return {}
            made = derive(src, missing)
            if made is None:
                return None
            for dest, data in made.items():
                trace(f"derive {dest.name}")
                store_entry(dest, data)
    except OSError as e:
        return {dest: ("E0652", describe(e, "write the mesh cache entry")) for _, _, dest in jobs}
    return {}


def derive(src: Path, jobs: list[tuple[tuple[MeshOp, ...], Path]]) -> dict[Path, bytes] | None:
    """The bytes of each job's cache entry (ops, entry path) from one read of `src`; None when
    the file is not one this path reproduces."""
    from mpc.core import mesh_arrays
    from mpc.core.cache import file_digest, trace

    try:
        data = src.read_bytes()
    except OSError:
        return None  # the trimesh path says why
    trace(f"parse {src.name} {file_digest(src)[:12]}")
    mesh = mesh_arrays.decode(data, src.suffix)
    if mesh is None:
        return None
    out: dict[Path, bytes] = {}
    for ops, dest in jobs:
        result = applied(mesh, ops)
        if dest.suffix == ".obj":
            name = mesh_arrays.obj_name(data, src.name)
            if name is None:
                return None
            out[dest] = mesh_arrays.encode_obj(result, name)
        else:
            out[dest] = mesh_arrays.encode_stl(result)
    return out
