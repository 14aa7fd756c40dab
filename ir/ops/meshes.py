"""Ops on every mesh of the robot: decimation (`reduce_meshes`), baking scales (`apply_scale`).

They record mesh ops on the mesh values; the work is done once, at emission."""

from __future__ import annotations

from dataclasses import replace

from mpc.core.record import record
from mpc.ir.geometry import Mesh, ReduceMesh, ScaleMesh
from mpc.ir.ops.base import Effects, Op, Phase
from mpc.ir.robot import Robot


def _map_meshes(robot: Robot, edit) -> Robot:
    links = {}
    for name, link in robot.links.items():
        links[name] = replace(
            link,
            visuals=tuple(replace(v, geometry=edit(v.geometry)) if isinstance(v.geometry, Mesh) else v
                          for v in link.visuals),
            collisions=tuple(replace(c, geometry=edit(c.geometry)) if isinstance(c.geometry, Mesh) else c
                             for c in link.collisions))
    return replace(robot, links=links)


@record(kw_only=True)
class ReduceMeshes(Op):
    """Decimate every mesh (quadric decimation, fast-simplification) to `faces` faces each,
    or to `ratio` of its faces."""

    PHASE = Phase.MESHES

    faces: int | None = None
    ratio: float | None = None

    WHAT = "reduce_meshes"

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        op = ReduceMesh(faces=self.faces, ratio=self.ratio)
        return _map_meshes(robot, lambda m: replace(m, ops=(*m.ops, op)))


@record(kw_only=True)
class ApplyScale(Op):
    """Bake each mesh's scale into its file; the element then has none."""

    PHASE = Phase.MESHES

    WHAT = "apply_scale"

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        def bake(m: Mesh) -> Mesh:
            if m.scale is None or m.scale == (1.0, 1.0, 1.0):
                return replace(m, scale=None) if m.scale is not None else m
            return replace(m, scale=None, ops=(*m.ops, ScaleMesh(m.scale)))

        return _map_meshes(robot, bake)
