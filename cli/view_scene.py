"""ir.Robot → a viser scene: one frame per link (posed by forward kinematics), its visuals,
collisions and axes under it; `pose(q)` moves the frames. No GUI and no server of its own
(cli/view.py makes them). Meshes go through the mesh cache as OBJ, their recorded ops
applied, as every export does.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from mpc.backends import meshes
from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere
from mpc.ir.kinematics import pose_matrix
from mpc.ir.robot import Collision, Joint, Material, Robot, Visual
from mpc.ir.tree import depth_first

RGBA = tuple[float, float, float, float]
GREY: RGBA = (0.55, 0.55, 0.58, 1.0)
COLLISION: RGBA = (0.95, 0.55, 0.1, 0.45)
GHOST: RGBA = (0.2, 0.45, 0.95, 0.3)
MOVABLE = ("revolute", "continuous", "prismatic")


def movable(robot: Robot) -> list[Joint]:
    """The joints that get a slider: one degree of freedom and no mimic (those follow)."""
    return [j for j, _ in depth_first(robot) if j is not None and j.type in MOVABLE and j.mimic is None]


def link_poses(robot: Robot, q: Mapping[str, float]) -> dict[str, np.ndarray]:
    """Each link's pose in the root frame (4×4) at joint values `q` (others 0; mimic joints
    follow their joint)."""
    values = dict(q)
    for joint in robot.joints.values():
        m = joint.mimic
        if m is not None:
            values[joint.name] = (m.offset or 0.0) + (1.0 if m.multiplier is None else m.multiplier) \
                * values.get(m.joint, 0.0)
    out = {robot.root: np.eye(4)}
    for joint, link in depth_first(robot):
        if joint is None:
            continue
        motion = np.eye(4)
        value = values.get(joint.name, 0.0)
        axis = np.asarray(joint.axis or (1.0, 0.0, 0.0), dtype=float)
        if joint.type in ("revolute", "continuous") and value:
            motion[:3, :3] = Rotation.from_rotvec(axis / np.linalg.norm(axis) * value).as_matrix()
        elif joint.type == "prismatic" and value:
            motion[:3, 3] = axis / np.linalg.norm(axis) * value
        out[link] = out[joint.parent] @ pose_matrix(joint.origin) @ motion
    return out


def wxyz(X: np.ndarray) -> tuple[float, float, float, float]:
    x, y, z, w = Rotation.from_matrix(X[:3, :3]).as_quat()
    return (float(w), float(x), float(y), float(z))


def node_name(text: str) -> str:
    """A link name as one part of a viser scene path."""
    return text.replace("/", "_") or "_"


@record(frozen=False)
class RobotScene:
    """A robot drawn in a viser server under `/<prefix>/`: handles by link and by kind."""

    robot: Robot
    prefix: str
    frames: dict[str, Any] = field(default_factory=dict)
    visuals: list[Any] = field(default_factory=list)
    collisions: list[Any] = field(default_factory=list)
    corners: list[np.ndarray] = field(default_factory=list)  # of each visual, in the root frame at q = 0

    def bounds(self) -> tuple[np.ndarray, float]:
        """The centre and the radius of the visuals at the zero pose (the camera's aim)."""
        if not self.corners:
            return np.zeros(3), 1.0
        points = np.concatenate(self.corners)
        lo, hi = points.min(axis=0), points.max(axis=0)
        return (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 0.05)

    def pose(self, q: Mapping[str, float]) -> None:
        """Move every link frame to its pose at joint values `q`."""
        for link, X in link_poses(self.robot, q).items():
            frame = self.frames.get(link)
            if frame is not None:
                frame.position, frame.wxyz = tuple(float(c) for c in X[:3, 3]), wxyz(X)

    def show(self, handles: Iterable[Any], visible: bool) -> None:
        for handle in handles:
            handle.visible = visible


def _material(robot: Robot, visual: Visual) -> RGBA:
    m: Material | None = visual.inline_material or robot.materials.get(visual.material or "")
    return tuple(m.rgba) if m is not None and m.rgba is not None else GREY  # type: ignore[return-value]


def _trimesh(shape: Visual | Collision, files: Mapping[Any, str], folder: Path,
             loaded: dict[str, Any]) -> Any:
    """The shape's geometry as a trimesh in its link's frame (its origin applied)."""
    import trimesh

    g = shape.geometry
    match g:
        case Box():
            mesh = trimesh.creation.box(extents=g.size)
        case Cylinder():
            mesh = trimesh.creation.cylinder(radius=g.radius, height=g.length, sections=32)
        case Sphere():
            mesh = trimesh.creation.icosphere(subdivisions=2, radius=g.radius)
        case Mesh():
            rel = files[meshes.key(g)]
            if rel not in loaded:
                loaded[rel] = trimesh.load(folder / rel, force="mesh", process=False)
            mesh = loaded[rel].copy()
            if g.scale is not None:
                mesh.apply_scale(g.scale)
        case _:
            return None
    mesh.apply_transform(pose_matrix(shape.origin))
    return mesh


def add_robot(server: Any, robot: Robot, prefix: str, workdir: Path, sink: Sink, span: Span,
              ghost: bool = False) -> RobotScene | None:
    """Draw `robot` into `server` under `/<prefix>/`; a ghost is drawn translucent, one colour,
    without collisions. None when its meshes cannot be made (the diagnostic is in `sink`)."""
    files = meshes.write(robot, "obj", (), workdir, sink, span)
    if files is None:
        return None
    scene = RobotScene(robot, prefix)
    loaded: dict[str, Any] = {}
    at_zero = link_poses(robot, {})
    for _, link in depth_first(robot):
        base = f"/{prefix}/{node_name(link)}"
        scene.frames[link] = server.scene.add_frame(base, show_axes=False, axes_length=0.06,
                                                    axes_radius=0.003)
        shapes: list[tuple[str, Visual | Collision, RGBA]] = [
            ("visual", v, GHOST if ghost else _material(robot, v)) for v in robot.links[link].visuals]
        if not ghost:
            shapes += [("collision", c, COLLISION) for c in robot.links[link].collisions]
        for i, (kind, shape, rgba) in enumerate(shapes):
            mesh = _trimesh(shape, files, workdir, loaded)
            if mesh is None or len(mesh.faces) == 0:
                continue
            handle = server.scene.add_mesh_simple(
                f"{base}/{kind}_{i}", np.asarray(mesh.vertices, dtype=np.float32),
                np.asarray(mesh.faces, dtype=np.uint32), color=tuple(int(255 * c) for c in rgba[:3]),
                opacity=None if rgba[3] >= 1 else float(rgba[3]), side="double" if rgba[3] < 1 else "front",
                visible=kind == "visual", cast_shadow=False, receive_shadow=False)
            (scene.visuals if kind == "visual" else scene.collisions).append(handle)
            if kind == "visual":
                X = at_zero[link]
                scene.corners.append(np.asarray(mesh.bounds) @ X[:3, :3].T + X[:3, 3])
    scene.pose({})
    return scene
