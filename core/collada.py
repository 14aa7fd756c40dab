"""COLLADA (.dae) file → a triangle mesh in metres, and the broken references ignored to get it.

pycollada drops a node's geometry when the node binds a material whose effect or texture is
missing (a texture that was never shipped with the model, as in example-robot-data's ANYmal
foot), and trimesh then finds no triangles at all. The triangles themselves are intact, so such
a file is read once more without its material bindings, and what was broken is reported. A
file whose references all resolve is read as trimesh reads it. Nothing here writes files.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import trimesh

from mpc.core.span import hardened_parser


def read(path: Path) -> tuple[trimesh.Trimesh, tuple[str, ...]]:
    """The triangles of a DAE file, scaled to metres by its `<unit>`, and the broken references
    (pycollada's messages, sorted) that were ignored to read them; raises what pycollada and
    lxml raise for a file that is not COLLADA at all."""
    import collada

    data = path.read_bytes()
    ignore = [collada.common.DaeBrokenRefError, collada.common.DaeUnsupportedError]
    errors = collada.Collada(io.BytesIO(data), ignore=ignore).errors
    broken = tuple(sorted({str(getattr(e, "msg", e)) for e in errors}))
    if broken:
        data = _without_material_bindings(data)
    mesh = trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)
    mesh.apply_scale(_unit(data))
    return mesh, broken


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
