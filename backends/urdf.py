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
from mpc.ir.program import UrdfExport
from mpc.ir.robot import Robot

__all__ = ["emit", "read", "to_string"]


def emit(robot: Robot, export: UrdfExport, out: Path, sink: Sink) -> None:
    """Write the URDF of `robot` and its meshes under `out`, as `export` asks."""
    files = meshes.plan(robot, export.mesh_format, sink, export.span)
    if files is None or not meshes.copy(files, out, sink, export.span):
        return

    def mesh_name(mesh: Mesh) -> str:
        return "../" + files[meshes.key(mesh)]

    write_path(out / "urdf" / f"{robot.name}.urdf", to_string(robot, mesh_name))
