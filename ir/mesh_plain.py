"""A mesh's reflections and scales applied to its arrays (core/mesh_arrays.py) as trimesh
applies them: the mesh ops that need no trimesh. The mesh cache's plain path
(backends/plain_meshes.py) and the collision shapes of the bitmasks (ir/bitmask.py) share it."""

from __future__ import annotations

from typing import TYPE_CHECKING

from mpc.ir.geometry import MeshOp, ReflectMesh, ScaleMesh

if TYPE_CHECKING:
    from mpc.core.mesh_arrays import Arrays


def is_plain(ops: tuple[MeshOp, ...]) -> bool:
    return all(isinstance(op, ReflectMesh | ScaleMesh) for op in ops)


def applied(arrays: Arrays, ops: tuple[MeshOp, ...]) -> Arrays:
    """The mesh after its plain ops (`is_plain`), in order."""
    import numpy as np

    from mpc.core.mesh_arrays import scale_matrix, transform

    for op in ops:
        if isinstance(op, ReflectMesh):
            matrix = np.eye(4)
            matrix[op.axis, op.axis] = -1.0
        else:
            assert isinstance(op, ScaleMesh)
            matrix = scale_matrix(np.asarray(op.scale))
        arrays = transform(arrays, matrix)
    return arrays
