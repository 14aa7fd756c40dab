"""Mesh file formats that trimesh does not read, by suffix: `suffix → (bytes → trimesh.Trimesh)`.

The backends that know such a format register its reader here (backends/__init__.py: MARS's
binary OBJ, `.bobj`), so that ir/mesh_props.py reads every mesh without importing a backend.
Nothing is imported here: `mpc check` loads this module with the backends package.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

MESH_READERS: dict[str, Callable[[bytes], Any]] = {}
