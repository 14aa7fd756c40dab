"""COLLADA (.dae) file → a triangle mesh in metres, and the broken references ignored to get it.

pycollada drops a node's geometry when the node binds a material whose effect or texture is
missing (a texture that was never shipped with the model, as in example-robot-data's ANYmal
foot), and trimesh then finds no triangles at all. The triangles themselves are intact, so such
a file is read once more without its material bindings, and what was broken is reported. A
file whose references all resolve is read as trimesh reads it. Nothing here writes files.

What trimesh writes as COLLADA (through pycollada) is stamped with the time of writing and
random ids; `stable` makes it the same bytes for the same mesh (mpc's outputs are).
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.core.mesh_arrays import unit
from mpc.core.span import hardened_parser

if TYPE_CHECKING:  # trimesh is imported where a mesh is read: `material_colours` from the cache needs none
    import collada
    import trimesh

RGBA = tuple[float, float, float, float]
COLOURS = "1"  # changes when the colours read change, so old cache entries go unused


def read(path: Path) -> tuple[trimesh.Trimesh, tuple[str, ...]]:
    """The triangles of a DAE file, scaled to metres by its `<unit>`, and the broken references
    (pycollada's messages, sorted) that were ignored to read them; raises what pycollada and
    lxml raise for a file that is not COLLADA at all.

    pycollada parses the file once (twice only when references are broken), and its document
    is turned into a mesh as trimesh's own COLLADA loader does, so the triangles, texture
    coordinates and names are those that `trimesh.load` gives.
    """
    document, data, broken = _document(path)
    mesh = _as_trimesh(document)
    mesh.apply_scale(unit(data))
    return mesh, broken


def _kinds() -> tuple[tuple[type, ...], tuple[type, ...]]:
    """The errors pycollada may find that mpc ignores (broken and unsupported references,
    reported as W0605), and those that trimesh's loader ignores too: a file with one of the
    latter only is refused, as when pycollada raised it."""
    from collada import common

    broken = (common.DaeBrokenRefError, common.DaeUnsupportedError)
    return broken, (*broken, common.DaeError, common.DaeIncompleteError, common.DaeMalformedError)


def _parse(data: bytes, strict: bool = True) -> collada.Collada:
    """pycollada's document of `data`; strict: raises the first error that is not a broken
    reference (the file is refused), else ignores what trimesh's loader ignores."""
    import collada

    broken, ignored = _kinds()
    document = collada.Collada(io.BytesIO(data), ignore=list(ignored))
    refused = next((e for e in document.errors if not isinstance(e, broken)), None)
    if strict and refused is not None:
        raise refused
    return document


def _as_trimesh(document: collada.Collada) -> trimesh.Trimesh:
    """The document's geometry as one mesh, as `trimesh.load(…, force="mesh", process=False)`
    makes it (trimesh.exchange.dae.load_collada, given the parsed document)."""
    return _scene(document).to_mesh()


def _scene(document: collada.Collada) -> trimesh.Scene:
    """The document as trimesh's scene: one geometry per primitive, each with its material
    (a material coloured by a texture has no `baseColorFactor`: no colour mpc can draw)."""
    import collada as pycollada
    import numpy as np
    from trimesh.exchange import dae
    from trimesh.exchange.load import _load_kwargs

    materials = {}
    for m in document.materials:
        materials[m.id] = dae._parse_material(m.effect, None)
        if isinstance(m.effect.diffuse, pycollada.material.Map):
            materials[m.id].baseColorFactor = None
    per_unit = document.assetInfo.unitmeter if document.assetInfo is not None else None
    metadata = ({"units": "meters"} if per_unit is None or np.isclose(per_unit, 1.0)
                else {"units": f"{per_unit} * meters"})
    meshes: dict = {}
    counts: dict = {}
    graph: list = []
    for node in document.scene.nodes:
        dae._parse_node(node=node, parent_matrix=dae._EYE, material_map=materials, meshes=meshes,
                        meshes_count=counts, graph=graph, resolver=None, metadata=metadata)
    return _load_kwargs(process=False, **{"class": "Scene", "graph": graph, "geometry": meshes})


def _document(path: Path) -> tuple[collada.Collada, bytes, tuple[str, ...]]:
    """The parsed file, the bytes parsed and its broken references: when there are any, the
    file is parsed again without its material bindings (see the module's docstring)."""
    data = path.read_bytes()
    document = _parse(data)
    broken = tuple(sorted({str(getattr(e, "msg", e)) for e in document.errors}))
    if broken:
        data = _without_material_bindings(data)
        document = _parse(data, strict=False)
    return document, data, broken


def _colour(mesh: trimesh.Trimesh) -> RGBA | None:
    """The rgba (0..1) of a primitive's material, None when it has none or only a texture."""
    material = getattr(mesh.visual, "material", None)
    factor = getattr(material, "baseColorFactor", None)
    if factor is None:
        return None
    return tuple(round(int(c) / 255, 6) for c in factor)  # type: ignore[return-value]


_PARTS: dict[tuple[str, str], list[tuple[RGBA | None, trimesh.Trimesh]]] = {}


def material_parts(path: Path) -> list[tuple[RGBA | None, trimesh.Trimesh]]:
    """The file's triangles in metres, one mesh per material colour (None: no colour), in the
    order the colours first appear; the triangles of all parts are those `read` gives. Kept
    for the last file read in this process: the parts of one file are asked for one by one."""
    import numpy as np
    import trimesh

    from mpc.core.cache import file_digest

    key = (str(path), file_digest(path))
    if key not in _PARTS:
        document, data, _ = _document(path)
        metres = unit(data)
        groups: dict[RGBA | None, list[trimesh.Trimesh]] = {}
        for piece in _scene(document).dump():
            groups.setdefault(_colour(piece), []).append(piece)
        parts = []
        for colour, pieces in groups.items():
            vertices, faces, offset = [], [], 0
            for piece in pieces:
                vertices.append(np.asarray(piece.vertices))
                faces.append(np.asarray(piece.faces) + offset)
                offset += len(piece.vertices)
            mesh = trimesh.Trimesh(np.concatenate(vertices), np.concatenate(faces), process=False)
            mesh.apply_scale(metres)
            parts.append((colour, mesh))
        _PARTS.clear()
        _PARTS[key] = parts
    return _PARTS[key]


def material_colours(path: Path) -> tuple[RGBA | None, ...]:
    """The colours of `material_parts`, in their order; kept in the cache (`meshes/materials/`),
    so that a render that finds its split meshes in the mesh cache parses nothing."""
    import json

    from mpc.core.cache import cache_dir, file_digest, load_entry, store_entry

    digest = file_digest(path)
    entry = cache_dir("meshes") / "materials" / f"{digest}-{COLOURS}.json"
    try:
        data, _ = load_entry(entry)
        if data is not None:
            return tuple(None if c is None else tuple(c) for c in json.loads(data))
    except (OSError, ValueError, TypeError):
        pass  # unusable: computed again
    colours = tuple(colour for colour, _ in material_parts(path))
    with contextlib.suppress(OSError):  # a read-only cache: computed again next time
        store_entry(entry, json.dumps(colours).encode())
    return colours


def _without_material_bindings(data: bytes) -> bytes:
    """The document with every `<bind_material>` removed, so that pycollada keeps the geometry
    of nodes whose materials cannot be resolved (materials only colour a mesh)."""
    from lxml import etree

    root = etree.fromstring(data, hardened_parser(huge=True))
    for binding in list(root.iter("{*}bind_material")):
        binding.getparent().remove(binding)
    return etree.tostring(root)


_STAMP = re.compile(rb"<(created|modified)>[^<]*</(created|modified)>")
_RANDOM_ID = re.compile(rb'="(#?)([0-9a-f]{32})"')  # uuid4().hex, as pycollada names what it writes


def stable(data: bytes) -> bytes:
    """trimesh's COLLADA export, byte for byte the same for the same mesh: the asset's dates
    become the epoch (a mesh is kept in the cache across builds, so no build's
    SOURCE_DATE_EPOCH is its own) and the random ids `id0`, `id1`, … in order of appearance."""
    data = _STAMP.sub(lambda m: b"<%s>1970-01-01T00:00:00</%s>" % (m[1], m[1]), data)
    names: dict[bytes, bytes] = {}

    def rename(m: re.Match[bytes]) -> bytes:
        new = names.setdefault(m[2], b"id%d" % len(names))
        return b'="' + m[1] + new + b'"'

    return _RANDOM_ID.sub(rename, data)
