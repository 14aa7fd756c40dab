"""ir.Robot → `render/<pose>_<view>.png`: pictures of the robot drawn headless by MuJoCo.

For each pose (the zero pose `zero` and the named poses, or those the entry lists) and each
view, the camera frames every drawn shape at that pose. The PNGs carry no date: the same
model gives the same bytes. No EGL is E0570 naming what to install; it draws nothing else
(no animation, no textures: the MJCF holds colours only).
"""

from __future__ import annotations

import re
import tempfile
from collections.abc import Mapping
from pathlib import Path

from mpc.backends.scene import GLMissing, Scene, frame, missing_gl_hint, png
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.files import confined
from mpc.core.programs import note_loaded_libraries
from mpc.ir.kinematics import zero_within_limits
from mpc.ir.program import RenderExport
from mpc.ir.robot import Robot

ZERO = "zero"  # the pose with every joint at 0
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]")


def file_stem(name: str) -> str:
    """A pose or view name as part of a file name: only letters, digits, `_`, `.` and `-`
    (a pose name is free text; it must not reach outside `render/`)."""
    stem = _UNSAFE.sub("_", name).lstrip(".")
    return stem or "_"


def pose_values(robot: Robot, pose: str) -> dict[str, float]:
    """The joint values of a pose (`zero`: none), with mimic joints following their joint.
    A joint the pose does not name is at 0, or at the limit nearest 0 when its limits leave
    0 out (`zero_within_limits`, as `mpc view` starts it)."""
    named = robot.poses.get(pose, {}) if pose != ZERO or ZERO in robot.poses else {}
    values = {**zero_within_limits(robot), **named}
    for joint in robot.joints.values():
        m = joint.mimic
        if m is not None and m.joint in values and joint.name not in values:
            values[joint.name] = (m.offset or 0.0) + (1.0 if m.multiplier is None else m.multiplier) \
                * values[m.joint]
    return values


def poses_of(robot: Robot, export: RenderExport, sink: Sink) -> list[str] | None:
    """The poses to draw, or None after E0575 (a name the robot has no pose of)."""
    if export.poses == ("all",):
        return [ZERO, *sorted(p for p in robot.poses if p != ZERO)]
    known = {ZERO, *robot.poses}
    unknown = [p for p in export.poses if p not in known]
    for name in unknown:
        sink.error(export.span, "E0575", f"render pose '{name}' is neither '{ZERO}' nor a pose of "
                   f"robot '{robot.name}'{did_you_mean(name, known)}",
                   hint="poses are named in the `poses` section")
    return None if unknown else list(dict.fromkeys(export.poses))


def clamped_note(robot: Robot) -> str:
    """What the pictures draw other than at 0, for a warning or a note: "" when nothing."""
    moved = zero_within_limits(robot)
    if not moved:
        return ""
    listed = ", ".join(f"'{name}' at {value:g}" for name, value in sorted(moved.items()))
    return (f"{len(moved)} joint{'s' * (len(moved) > 1)} of robot '{robot.name}' cannot be at 0 within "
            f"{'their' if len(moved) > 1 else 'its'} limits and {'are' if len(moved) > 1 else 'is'} "
            f"drawn at the limit nearest 0: {listed}")


def draw_all(robot: Robot, export: RenderExport, sink: Sink) -> Mapping[str, bytes] | None:
    """{file name: PNG bytes} of every pose and view, or None after an error. W0590 names
    the joints drawn at a limit instead of at 0."""
    poses = poses_of(robot, export, sink)
    if poses is None:
        return None
    note = clamped_note(robot)
    if note:
        sink.warning(export.span, "W0590", note, hint="as `mpc view` starts them; name their values "
                     "in a pose to draw them elsewhere")
    out: dict[str, bytes] = {}
    with tempfile.TemporaryDirectory(prefix="mpc-render-") as work:
        scene = Scene.build(robot, Path(work), sink, export.span, export.geometry, export.background)
        if scene is None:
            return None
        try:
            for pose in poses:
                scene.pose(pose_values(robot, pose))
                points = scene.points()
                for view in export.views:
                    picture = scene.draw(frame(points, view, export.size), export.size)
                    out[f"{file_stem(pose)}_{view}.png"] = png(picture)
        except GLMissing as e:
            sink.error(export.span, "E0570", f"cannot draw robot '{robot.name}' without a display: "
                       f"MuJoCo found no EGL ({e})", hint=missing_gl_hint())
            return None
        finally:
            scene.close()
    return out


def emit(robot: Robot, export: RenderExport, out: Path, sink: Sink) -> None:
    """Write `out/render/<pose>_<view>.png` for every pose and view of the entry."""
    pictures = draw_all(robot, export, sink)
    if pictures is None:
        return
    note_loaded_libraries()  # EGL and Mesa drew them: a kept render depends on their files
    folder = confined(out, "render")
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in sorted(pictures.items()):
        confined(folder, name).write_bytes(data)
