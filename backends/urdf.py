"""The URDF backend: `read` a URDF file into the IR, `emit` a robot as URDF.

Output: `<out>/urdf/<robotname>.urdf`, meshes copied to `<out>/meshes/<format>/` and
referenced relative to the URDF file. What URDF cannot hold (motors, sensors, poses,
annotations, bitmasks, …) is in the SMURF written beside it (backends/smurf.py).
"""

from __future__ import annotations

from pathlib import Path

from mpc.backends.float_formats import URDF_KEYS, Formats
from mpc.backends.urdf_reader import read
from mpc.backends.urdf_writer import to_string
from mpc.backends.xml import write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.ir.program import UrdfExport
from mpc.ir.robot import Robot

__all__ = ["emit", "read", "to_string"]


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
    from mpc.backends import meshes  # hashlib, filecmp: `mpc check` only reads URDF
    from mpc.backends.mesh_paths import variants

    if not check(robot, export, sink):
        return
    prepared = meshes.for_export(robot, export, out, sink)
    if prepared is None:
        return
    robot, files = prepared
    formats = Formats(export.float_formats, URDF_KEYS) if export.float_formats else None
    for suffix, prefix in variants(export):
        write_path(confined(out, "urdf", f"{export.filename or robot.name}{suffix}.urdf"),
                   to_string(robot, meshes.namer(files, prefix), formats))
