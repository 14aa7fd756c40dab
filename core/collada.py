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

import io
import re
from pathlib import Path
from typing import TYPE_CHECKING

import trimesh

from mpc.core.span import hardened_parser

if TYPE_CHECKING:
    import collada


def read(path: Path) -> tuple[trimesh.Trimesh, tuple[str, ...]]:
    """The triangles of a DAE file, scaled to metres by its `<unit>`, and the broken references
    (pycollada's messages, sorted) that were ignored to read them; raises what pycollada and
    lxml raise for a file that is not COLLADA at all.

    pycollada parses the file once (twice only when references are broken), and its document
    is turned into a mesh as trimesh's own COLLADA loader does, so the triangles, texture
    coordinates and names are those that `trimesh.load` gives.
    """
    data = path.read_bytes()
    document = _parse(data)
    broken = tuple(sorted({str(getattr(e, "msg", e)) for e in document.errors}))
    if broken:
        data = _without_material_bindings(data)
        document = _parse(data, strict=False)
    mesh = _as_trimesh(document)
    mesh.apply_scale(_unit(data))
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
    import numpy as np
    from trimesh.exchange import dae
    from trimesh.exchange.load import _load_kwargs

    materials = {m.id: dae._parse_material(m.effect, None) for m in document.materials}
    unit = document.assetInfo.unitmeter
    metadata = {"units": "meters"} if unit is None or np.isclose(unit, 1.0) else {"units": f"{unit} * meters"}
    meshes: dict = {}
    counts: dict = {}
    graph: list = []
    for node in document.scene.nodes:
        dae._parse_node(node=node, parent_matrix=dae._EYE, material_map=materials, meshes=meshes,
                        meshes_count=counts, graph=graph, resolver=None, metadata=metadata)
    return _load_kwargs(process=False, **{"class": "Scene", "graph": graph, "geometry": meshes}).to_mesh()


def _without_material_bindings(data: bytes) -> bytes:
    """The document with every `<bind_material>` removed, so that pycollada keeps the geometry
    of nodes whose materials cannot be resolved (materials only colour a mesh)."""
    from lxml import etree

    root = etree.fromstring(data, hardened_parser(huge=True))
    for binding in list(root.iter("{*}bind_material")):
        binding.getparent().remove(binding)
    return etree.tostring(root)


def _unit(data: bytes) -> float:
    """Metres per unit of a COLLADA file (its <unit meter=…>), 1 when it has none."""
    m = re.search(rb"<unit\b[^>]*\bmeter=\"([0-9.eE+-]+)\"", data[:4096])
    return float(m.group(1)) if m else 1.0


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
