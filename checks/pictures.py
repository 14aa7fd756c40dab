"""The compiled model and its release → the visual diff of a test run: for each view, the
release and the new model drawn at the zero pose from one camera, the links that changed
beyond the tolerances coloured and the others grey, and a third picture overlaying both.

A link changed when it is new or gone, when its joint (parent, type, origin, axis) moved by
more than `distance` or turned by more than `rad`, when its mass changed by more than `mass`,
or when one of its shapes changed (kind, size or placement beyond the tolerances, or another
mesh file). A link's pose is its joint's origin, relative to its parent: a moved link is
coloured, the links it carries (which move with it) are not. It writes no file:
Protocol.write puts the pictures beside the protocol.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
from dataclasses import field
from pathlib import Path

import numpy as np

from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir import transforms as tf
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere, is_generated
from mpc.ir.program import RenderExport, Tolerances
from mpc.ir.robot import Joint, Link, Pose, Robot

# The reference palette: changed links in the release and in the new model; the others grey.
CHANGED_RELEASE = (0.15, 0.45, 0.95, 1.0)  # blue
CHANGED_NEW = (0.95, 0.35, 0.1, 1.0)  # orange
UNCHANGED = (0.62, 0.62, 0.62, 1.0)
FOLDER = "test_pictures"  # beside the protocol
DEFAULT_SIZE = (480, 360)
SIDES = ("release", "new", "overlay")
TREE = "kinematic_tree.pdf"  # the model's pdf export, its changed links coloured


@record(frozen=False)
class VisualDiff:
    """The pictures of a test run. files: {file name: PNG bytes} (written into FOLDER);
    views: the views drawn, in order; changed: {link: why}; problem: why nothing was drawn;
    notes: what the pictures show otherwise than asked (joints at a limit instead of at 0)."""

    files: dict[str, bytes] = field(default_factory=dict)
    views: tuple[str, ...] = ()
    changed: dict[str, str] = field(default_factory=dict)
    problem: str = ""
    notes: list[str] = field(default_factory=list)  # joints drawn at a limit instead of at 0

    def path(self, view: str, side: str) -> str:
        """A picture's path relative to the protocol."""
        return f"{FOLDER}/{view}_{side}.png"

    @property
    def tree(self) -> str:
        """The coloured kinematic tree's path relative to the protocol, or "" without one."""
        return f"{FOLDER}/{TREE}" if TREE in self.files else ""

    @property
    def drawn(self) -> bool:
        return any(name.endswith(".png") for name in self.files)


def turned(a: Pose | None, b: Pose | None) -> tuple[float, float]:
    """How far (m) and by what angle (rad) pose b lies from pose a."""
    pa, pb = a or Pose(), b or Pose()
    distance = float(np.linalg.norm(np.subtract(pa.xyz, pb.xyz)))
    R = tf.rpy_to_matrix(pa.rpy).T @ tf.rpy_to_matrix(pb.rpy)
    return distance, math.acos(max(-1.0, min(1.0, (float(np.trace(R)) - 1) / 2)))


def mesh_digest(mesh: Mesh) -> str:
    path = mesh.source.path
    if is_generated(mesh.source):  # made from shapes: its ops are all of it
        return mesh.source.uri + repr(mesh.ops)
    if path is None or not Path(path).is_file():
        return f"missing:{mesh.source.uri}"
    return hashlib.sha256(Path(path).read_bytes()).hexdigest() + repr(mesh.ops)


def _shape_changed(a: object, b: object, tol: Tolerances) -> bool:
    ga, gb = a.geometry, b.geometry  # type: ignore[attr-defined]
    if type(ga) is not type(gb):
        return True
    d, angle = turned(a.origin, b.origin)  # type: ignore[attr-defined]
    if d > tol.distance or angle > tol.rad:
        return True
    match ga:
        case Box():
            sizes = (ga.size, gb.size)
        case Cylinder():
            sizes = ((ga.radius, ga.length), (gb.radius, gb.length))
        case Sphere():
            sizes = ((ga.radius,), (gb.radius,))
        case Mesh():
            scale = (tuple(ga.scale or (1.0, 1.0, 1.0)), tuple(gb.scale or (1.0, 1.0, 1.0)))
            return scale[0] != scale[1] or mesh_digest(ga) != mesh_digest(gb)
        case _:
            return ga != gb
    return bool(np.max(np.abs(np.subtract(*sizes))) > tol.distance)


def _link_change(old: Link, new: Link, tol: Tolerances) -> str:
    mass = (old.inertial.mass if old.inertial else 0.0, new.inertial.mass if new.inertial else 0.0)
    if abs(mass[1] - mass[0]) > tol.mass:
        return f"mass {mass[0]:.4g} → {mass[1]:.4g} kg"
    for kind in ("visuals", "collisions"):
        a, b = getattr(old, kind), getattr(new, kind)
        if len(a) != len(b) or any(_shape_changed(x, y, tol) for x, y in zip(a, b, strict=True)):
            return f"{kind} changed"
    return ""


def _joint_change(old: Joint | None, new: Joint | None, tol: Tolerances) -> str:
    if old is None or new is None:
        return "" if old is new else "its joint changed"
    if (old.parent, old.type) != (new.parent, new.type):
        return f"its joint changed ({old.parent}, {old.type} → {new.parent}, {new.type})"
    d, angle = turned(old.origin, new.origin)
    if d > tol.distance or angle > tol.rad:
        return f"moved by {d:.4g} m, turned by {angle:.4g} rad"
    axes = (np.asarray(old.axis or (1.0, 0.0, 0.0)), np.asarray(new.axis or (1.0, 0.0, 0.0)))
    if new.type not in ("fixed", "floating") and float(np.linalg.norm(axes[0] - axes[1])) > tol.rad:
        return "its joint axis turned"
    return ""


def changed_links(old: Robot, new: Robot, tol: Tolerances) -> dict[str, str]:
    """{link: why} for every link of either model that changed beyond the tolerances."""
    old_joint, new_joint = ({j.child: j for j in r.joints.values()} for r in (old, new))
    out: dict[str, str] = {}
    for name in sorted({*old.links, *new.links}):
        if name not in old.links or name not in new.links:
            out[name] = "new link" if name in new.links else "removed"
            continue
        why = _joint_change(old_joint.get(name), new_joint.get(name), tol) or _link_change(
            old.links[name], new.links[name], tol)
        if why:
            out[name] = why
    return out


def draw(old: Robot, new: Robot, tol: Tolerances, render: RenderExport | None, sink: Sink,
         tree: bool = False, changed: dict[str, str] | None = None) -> VisualDiff:
    """The visual diff of `new` against its release `old`, drawn with the views and size of
    the model's render export (default: iso, front and side at 480×360); a reason instead of
    pictures when they cannot be drawn (no EGL, a model MuJoCo cannot load). tree: also the
    kinematic tree as a PDF with the changed links coloured (the model has a pdf export).
    changed: the links to colour, {name in either model: why} (default: changed_links)."""
    from mpc.backends.render import ZERO, clamped_note, pose_values
    from mpc.backends.scene import GLMissing, Scene, frame, png, side_by_side

    views = render.views if render is not None else ("iso", "front", "side")
    size = render.size if render is not None else DEFAULT_SIZE
    background = render.background if render is not None else (1.0, 1.0, 1.0)
    out = VisualDiff(views=tuple(views), changed=changed_links(old, new, tol) if changed is None else changed)
    quiet = Sink()  # what the build reported already (W0500 …) is not the diff's business
    span = Span.of_file(new.name)
    with tempfile.TemporaryDirectory(prefix="mpc-diff-") as work:
        # Both models in one scene: the meshes they share are read, compiled and drawn from once.
        scene = Scene.build(side_by_side([old, new]), Path(work), quiet, span, "visual", background)
        if scene is None:
            out.problem = "the models cannot be drawn: " + next(
                (d.message for d in quiet.diagnostics if d.severity.name == "ERROR"), "")
            return out
        sides = (("release", old, CHANGED_RELEASE), ("new", new, CHANGED_NEW))
        scene.colour({f"{i}/{link}": colour for i, (_, _, colour) in enumerate(sides)
                      for link in out.changed}, UNCHANGED)
        scene.pose({f"{i}/{joint}": value for i, (_, robot, _) in enumerate(sides)
                    for joint, value in pose_values(robot, ZERO).items()})  # at 0, or the limit nearest
        for side, robot, _ in sides:
            note = clamped_note(robot)
            if note:
                out.notes.append(f"The {side} model: {note}.")
        try:
            points = scene.points()
            for view in views:
                camera = frame(points, view, size)
                pictures = []
                for i in range(len(sides)):
                    scene.only(i)
                    pictures.append(scene.draw(camera, size))
                release, new_picture = pictures
                overlay = _overlay(release, new_picture)
                for side, picture in zip(SIDES, (release, new_picture, overlay), strict=True):
                    out.files[f"{view}_{side}.png"] = png(picture)
        except GLMissing as e:
            out.files, out.problem = {}, f"no EGL to draw with ({e})"
        finally:
            scene.close()
    if out.problem:
        sink.warning(span, "W0720", f"the test protocol has no pictures: {out.problem}")
    if tree:
        from mpc.backends.pdf import render_pdf, to_gv

        pdf = render_pdf(to_gv(new, changed=set(out.changed)))
        if isinstance(pdf, bytes):
            out.files[TREE] = pdf
        else:
            sink.warning(span, "W0721", f"the test protocol has no kinematic tree: {pdf}")
    return out


def _overlay(release: np.ndarray, new: np.ndarray) -> np.ndarray:
    """Both pictures in one, each at half strength: where only one model is drawn it shows
    faintly over the background, where both are their colours mix. Unchanged parts stay grey;
    a moved link shows twice, blue where the release had it and orange where it is now."""
    return ((release.astype(np.uint16) + new.astype(np.uint16) + 1) // 2).astype(np.uint8)


def render_export(exports: tuple[object, ...]) -> RenderExport | None:
    """The model's own render export (not a submodel's), if it has one."""
    return next((e for e in exports if isinstance(e, RenderExport) and not e.submodel), None)
