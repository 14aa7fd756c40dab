"""How a URDF or SDF file names its meshes: relative (`../meshes/…`) or as a ROS package
path (`package://<package>/meshes/…`, `ros_pathes`), and the copy with the other kind
(`copy_with_other_pathes`), which Phobos names `<file>_ros.<ext>` or `<file>_relpath.<ext>`."""

from __future__ import annotations

from mpc.ir.program import SdfExport, UrdfExport


def variants(export: UrdfExport | SdfExport) -> list[tuple[str, str]]:
    """(file name suffix, mesh path prefix) of each file the export writes: its own file
    first, then the copy. A submodel's meshes are in `submodels/<name>/` of the package."""
    inside = f"submodels/{export.submodel}/" if export.submodel else ""
    own = f"package://{export.ros_package}/{inside}" if export.ros_package else "../"
    out = [("", own)]
    if export.copy_package:
        if export.ros_package:
            out.append(("_relpath", "../"))
        else:
            out.append(("_ros", f"package://{export.copy_package}/{inside}"))
    return out
