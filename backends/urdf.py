"""The URDF backend: `read` a URDF file into the IR, `emit` a robot as URDF.

Output: `<out>/urdf/<robotname>.urdf`, meshes copied to `<out>/meshes/<format>/` and
referenced relative to the URDF file.
"""

from __future__ import annotations

from pathlib import Path

from mpc.backends import meshes
from mpc.backends.urdf_reader import read
from mpc.backends.urdf_writer import to_string
from mpc.backends.xml import write_path
from mpc.compiler.diagnostics import Sink
from mpc.ir.geometry import Mesh
from mpc.ir.numbers import zero_small
from mpc.ir.program import UrdfExport
from mpc.ir.robot import Robot

__all__ = ["emit", "read", "to_string"]


def left_out(robot: Robot) -> list[str]:
    """What the robot holds that URDF cannot: motors, sensors, annotations, …"""
    counts = {
        ("motor", "motors"): len(robot.motors), ("sensor", "sensors"): len(robot.sensors),
        ("pose", "poses"): len(robot.poses),
        ("loop-closure joint", "loop-closure joints"): len(robot.cut_joints),
        ("submechanism", "submechanisms"): len(robot.submechanisms),
        ("annotation category", "annotation categories"): len(robot.annotations),
        ("annotated link", "annotated links"): sum(bool(lk.annotations) for lk in robot.links.values()),
        ("annotated joint", "annotated joints"): sum(bool(j.annotations) for j in robot.joints.values()),
        ("collision bitmask or annotation", "collision bitmasks or annotations"): sum(
            bool(c.annotations) or c.bitmask is not None
            for lk in robot.links.values() for c in lk.collisions),
        ("annotated visual", "annotated visuals"): sum(
            bool(v.annotations) for lk in robot.links.values() for v in lk.visuals),
        ("material with more than a colour", "materials with more than a colour"): sum(
            any(getattr(m, k) is not None for k in ("ambient", "specular", "emissive", "shininess",
                                                     "transparency", "normal_texture"))
            or bool(m.annotations) for m in robot.materials.values()),
    }
    out = [f"{n} {words[n != 1]}" for words, n in counts.items() if n]
    if robot.submechanisms_file:
        out.append("the submechanisms file")
    return out


def check(robot: Robot, export: UrdfExport, sink: Sink) -> bool:
    """Whether `robot` can be written as valid URDF (urdfdom's rules)."""
    ok = True
    for joint in robot.joints.values():
        if joint.type in ("revolute", "prismatic") and (
                joint.limit is None or joint.limit.effort is None or joint.limit.velocity is None):
            sink.error(joint.span or export.span, "E0502", f"joint '{joint.name}' is {joint.type} but "
                       "has no limit with effort and velocity, which URDF requires",
                       hint=f"set them under `joints: {joint.name}: {{eff: …, vel: …}}`")
            ok = False
    return ok


def emit(robot: Robot, export: UrdfExport, out: Path, sink: Sink) -> None:
    """Write the URDF of `robot` and its meshes under `out`, as `export` asks."""
    if not check(robot, export, sink):
        return
    missing = left_out(robot)
    if missing:
        sink.warning(export.span, "W0500", "the URDF leaves out what URDF cannot hold: "
                     + ", ".join(missing) + "; no export that holds them (SMURF) is implemented yet")
    files = meshes.plan(robot, export.mesh_format, sink, export.span)
    if files is None or not meshes.copy(files, out, sink, export.span, robot):
        return
    for fmt in export.additional_meshes:  # written beside, referenced by nothing
        extra = meshes.plan(robot, fmt, sink, export.span)
        if extra is None or not meshes.copy(extra, out, sink, export.span, robot):
            return
    if export.enforce_zero:
        robot = zero_small(robot)
    prefix = f"package://{export.ros_package}/" if export.ros_package else "../"

    def mesh_name(mesh: Mesh) -> str:
        return prefix + files[meshes.key(mesh)]

    write_path(out / "urdf" / f"{export.filename or robot.name}.urdf", to_string(robot, mesh_name))
