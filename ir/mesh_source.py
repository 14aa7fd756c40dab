"""A mesh file → its triangles, parsed once per content hash, ever.

The first read of a file (by the sha256 of its bytes and its name) keeps its *normalized
form* in the cache (core/cache.py: `meshes/normal/`): an `.npz` of the vertices, triangles
and texture coordinates as the reader gave them, plus its names and material (an OBJ export
writes them), and the broken DAE references that were ignored to read it. Every later read,
by any build, process or output format, rebuilds the same trimesh from it, so what is
derived (STL, OBJ, bobj, a mirror, a hull) is byte for byte what the parsed file gives. Two
processes that need the same missing entry parse the file once (`single_flight`). A mesh
with more than the form carries (colours) is parsed each time. Nothing here writes outside
the cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import logging
from pathlib import Path

import numpy as np
import trimesh

# trimesh reports what it could not read through logging, with a traceback (an ASCII STL
# whose normals do not parse); mpc reports what matters as diagnostics, so they go nowhere.
logging.getLogger("trimesh").addHandler(logging.NullHandler())

FORM = "1"  # changes when the normalized form or the readers change, so old entries go unused


def read(path: Path, ignored: list[str] | None = None) -> trimesh.Trimesh:
    """The file's mesh as its reader gives it (unscaled, no ops); raises what the readers
    raise. ignored: receives the broken references of a DAE file that were ignored to read it."""
    from mpc.core.cache import file_digest, load_entry, notes_file, remove_entry, single_flight, touch_entry

    entry = entry_of(file_digest(path), path.name)
    with single_flight(entry):
        try:
            stored, bad = load_entry(entry)
            if bad is not None:
                remove_entry(entry)
        except OSError:  # a cache that cannot be used: the file is parsed
            stored = None
        if stored is not None:
            touch_entry(entry)  # used: a CI job passes it on
            notes = notes_file(entry)
            if ignored is not None and notes.is_file():
                ignored.extend(notes.read_text(encoding="utf-8").splitlines())
            return _checked(_rebuild(stored))
        broken: list[str] = []
        mesh = _parse(path, path.suffix.lower(), broken)
        _checked(mesh)
        if ignored is not None:
            ignored.extend(broken)
        form = _normalized(mesh)
        if form is not None:
            with contextlib.suppress(OSError):  # a read-only or full cache: parsed again next time
                _store(entry, form, broken)
        return mesh


def geometry_problem(mesh: trimesh.Trimesh) -> str | None:
    """Why the triangles a reader gave cannot be a mesh, or None. trimesh reads a broken
    file (an OBJ vertex of one number, an STL or DAE coordinate `nan`) into arrays of the
    wrong shape or into numbers that are not finite, and fails later, writing it; every
    consumer of the written file (a DAE that holds `nan`) refuses it."""
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        return f"its vertices are not points of 3 coordinates (an array of shape {vertices.shape})"
    if faces.ndim != 2 or faces.shape[1] != 3:
        return f"its triangles are not 3 vertices each (an array of shape {faces.shape})"
    if not np.isfinite(vertices).all():
        return "a vertex has a coordinate that is not a finite number (nan or inf)"
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        return f"a triangle names a vertex it does not have (it has {len(vertices)})"
    return None


def _checked(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    problem = geometry_problem(mesh)
    if problem is not None:
        raise ValueError(problem)
    return mesh


def entry_of(content: str, name: str) -> Path:
    """Where the cache keeps the normalized form of a file with this content (its sha256) and
    name: the readers name a mesh after its file when the format has no name for it (an OBJ
    export writes that name), and read it by its extension."""
    from mpc.core.cache import cache_dir

    digest = hashlib.sha256(f"{content}|{FORM}|{name}".encode()).hexdigest()
    return cache_dir("meshes") / "normal" / f"{digest}.npz"


def _parse(path: Path, suffix: str, broken: list[str]) -> trimesh.Trimesh:
    from mpc.core.cache import file_digest, trace

    trace(f"parse {path.name} {file_digest(path)[:12]}")
    if suffix == ".bobj":
        from mpc.core import bobj

        return bobj.loads(path.read_bytes())
    if suffix == ".dae":
        from mpc.core import collada

        mesh, found = collada.read(path)
        broken.extend(found)
        return mesh
    return trimesh.load(path, force="mesh", process=False)


def _normalized(mesh: trimesh.Trimesh) -> bytes | None:
    """The npz of what the exports and ops read from the mesh; None when it has more (vertex
    or face colours, normals from the file, metadata that is no text or number): such a mesh
    is parsed each time. A texture image is not kept: no output reads it (an OBJ names its
    material file, which mpc does not write), nor does any mesh op."""
    from trimesh.visual import ColorVisuals, TextureVisuals
    from trimesh.visual.material import SimpleMaterial

    metadata = {k: v for k, v in mesh.metadata.items() if isinstance(v, str | int | float)}
    if len(metadata) != len(mesh.metadata) or "vertex_normals" in mesh._cache.cache:
        return None
    arrays: dict[str, np.ndarray] = {"vertices": np.asarray(mesh.vertices), "faces": np.asarray(mesh.faces)}
    meta: dict[str, object] = {"metadata": metadata}
    visual = mesh.visual
    if isinstance(visual, ColorVisuals) and visual.kind is None:
        pass  # no colours
    elif isinstance(visual, TextureVisuals):
        meta["texture"] = True
        if visual.uv is not None:
            arrays["uv"] = np.asarray(visual.uv)
        material = visual.material
        if material is not None:
            simple = material.to_simple() if hasattr(material, "to_simple") else material
            if not isinstance(simple, SimpleMaterial):
                return None
            try:
                meta["material"] = {"name": str(simple.name), "glossiness": float(simple.glossiness),
                                    **{k: np.asarray(getattr(simple, k)).tolist()
                                       for k in ("ambient", "diffuse", "specular")}}
            except (TypeError, ValueError):  # a material with parts missing: not kept
                return None
    else:
        return None
    arrays["meta"] = np.frombuffer(json.dumps(meta, sort_keys=True).encode(), dtype=np.uint8)
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


def _rebuild(data: bytes) -> trimesh.Trimesh:
    from trimesh.visual import TextureVisuals
    from trimesh.visual.material import SimpleMaterial

    with np.load(io.BytesIO(data), allow_pickle=False) as z:
        meta = json.loads(z["meta"].tobytes())
        mesh = trimesh.Trimesh(z["vertices"], z["faces"], process=False, metadata=meta["metadata"])
        if meta.get("texture"):
            material = meta.get("material")
            mesh.visual = TextureVisuals(
                uv=z["uv"] if "uv" in z.files else None,
                material=None if material is None else SimpleMaterial(**material))
    return mesh


def _store(entry: Path, form: bytes, broken: list[str]) -> None:
    from mpc.core.cache import notes_file, store_entry
    from mpc.core.files import write_atomic

    if broken:  # written before the entry, so that an entry never lacks its record
        write_atomic(notes_file(entry), "".join(f"{line}\n" for line in sorted(set(broken))))
    store_entry(entry, form)
