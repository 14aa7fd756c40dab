"""The formats mpc reads and writes: one descriptor each, in one table (`FORMATS`).

A descriptor names what the rest of mpc asks of a format: its IR export record, the function
that writes it, the function that reads it (formats that are also inputs) and the suffixes
that recognise its files, whether its outputs live in the build cache, the numbers
`float_fmt_dict` may format, its meshes, and what it cannot hold (W0500, backends/holds.py).
Lowering (compiler/lower_exports.py and its table compiler/export_formats.py), the driver,
the build cache and the input readers ask the table, never a chain of format names.

Every name here is imported as a name, so import-linter sees it. The writers and readers are
small functions that import their backend when called: a format's libraries (NumPy, SciPy,
trimesh, lxml) are loaded only when it is used, and `mpc check` loads none.
Adding a format: specs/layers.md, "Adding a format".
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mpc.core.record import record
from mpc.ir import program
from mpc.ir.float_format_keys import MJCF_KEYS, SDF_KEYS, URDF_KEYS

if TYPE_CHECKING:
    from mpc.backends.holds import Tally
    from mpc.core.diagnostics import Sink
    from mpc.core.packages import PackageResolver
    from mpc.ir.robot import Robot

Write = Callable[["Robot", Any, Path, "Sink"], None]
Read = Callable[[Path, "Sink", "PackageResolver | None"], "Robot | None"]


@record
class Meshes:
    """A format that writes the meshes its file references (backends/meshes.py `for_export`):
    what `mesh_format: input_type` becomes for it (empty: each mesh's own format)."""

    input_type: str = ""


@record
class Format:
    """One format (see the module's docstring).

    numbers: what one of `float_keys` is in the format's file ("attribute of a URDF"), for E0530.
    package_paths: whether its file may hold `package://` mesh paths (`ros_pathes`).
    cut_joints: why `include_cut_joints` means nothing to the format, or "" when it is an option.
    exact_inertials: whether its consumer forgives no rounding, so that `correct_inertials`
    corrects exactly (SDFormat, MuJoCo).
    in_smurf: whether a SMURF can link its file (`link_in_smurf`).
    holds: the table of what the format cannot hold (None: it leaves nothing out to report),
    loaded with its backend.
    """

    name: str
    record: type | None = None
    write: Write | None = None
    read: Read | None = None
    suffixes: tuple[str, ...] = ()
    kept: bool = False
    float_keys: frozenset[str] = frozenset()
    numbers: str = ""
    meshes: Meshes | None = None
    package_paths: bool = False
    cut_joints: str = ""
    exact_inertials: bool = False
    in_smurf: bool = False
    holds: Callable[[], Sequence[Tally]] | None = None


# The writers and readers: each imports its backend only when called.

def _write_urdf(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import urdf

    urdf.emit(robot, export, out, sink)


def _read_urdf(path: Path, sink: Sink, resolver: PackageResolver | None) -> Robot | None:
    from mpc.backends import urdf_reader

    return urdf_reader.read(path, sink, resolver)


def _write_sdf(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import sdf

    sdf.emit(robot, export, out, sink)


def _read_sdf(path: Path, sink: Sink, resolver: PackageResolver | None) -> Robot | None:
    from mpc.backends import sdf_reader

    return sdf_reader.read(path, sink, resolver)


def _sdf_holds() -> Sequence[Tally]:
    from mpc.backends import sdf

    return sdf.CANNOT_HOLD


def _write_mjcf(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import mjcf

    mjcf.emit(robot, export, out, sink)


def _read_mjcf(path: Path, sink: Sink, resolver: PackageResolver | None) -> Robot | None:
    from mpc.backends import mjcf_reader

    return mjcf_reader.read(path, sink, resolver)


def _mjcf_holds() -> Sequence[Tally]:
    from mpc.backends import mjcf

    return mjcf.CANNOT_HOLD


def _write_usd(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import usd

    usd.emit(robot, export, out, sink)


def _usd_holds() -> Sequence[Tally]:
    from mpc.backends import usd

    return usd.CANNOT_HOLD


def _write_smurf(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import smurf

    smurf.emit(robot, export, out, sink)


def _read_smurf(path: Path, sink: Sink, resolver: PackageResolver | None) -> Robot | None:
    from mpc.backends import smurf_reader

    return smurf_reader.read(path, sink, resolver)


def _write_pdf(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import pdf

    pdf.emit(robot, export, out, sink)


def _write_render(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import render

    render.emit(robot, export, out, sink)


def _write_joint_limits(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import joint_limits

    joint_limits.emit(robot, export, out, sink)


def _write_kccd(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import kccd

    kccd.emit(robot, export, out, sink)


def _write_ros_package(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    from mpc.backends import ros_package

    ros_package.emit(robot, export, out, sink)


_FORMATS = (
    Format("urdf", program.UrdfExport, _write_urdf, _read_urdf, (".urdf",), kept=True,
           float_keys=URDF_KEYS, numbers="attribute of a URDF", meshes=Meshes(), package_paths=True,
           cut_joints="URDF cannot hold loops", in_smurf=True),
    Format("sdf", program.SdfExport, _write_sdf, _read_sdf, (".sdf",), kept=True,
           float_keys=SDF_KEYS, numbers="element of an SDF", meshes=Meshes(), package_paths=True,
           exact_inertials=True, in_smurf=True, holds=_sdf_holds),
    Format("mjcf", program.MjcfExport, _write_mjcf, _read_mjcf, (".xml", ".mjcf"), kept=True,
           float_keys=MJCF_KEYS,
           numbers="attribute of an MJCF", meshes=Meshes(input_type="obj"),
           cut_joints="MJCF always closes loops with equality constraints", exact_inertials=True,
           holds=_mjcf_holds),
    Format("usd", program.UsdExport, _write_usd, kept=True, holds=_usd_holds),
    Format("smurf", program.SmurfExport, _write_smurf, _read_smurf, (".smurf",), kept=True),
    Format("pdf", program.PdfExport, _write_pdf, kept=True),
    Format("render", program.RenderExport, _write_render, kept=True),
    Format("joint_limits", program.JointLimitsExport, _write_joint_limits, kept=True),
    Format("kccd", program.KccdExport, _write_kccd, kept=True),
    Format("ros_package", program.RosPackageExport, _write_ros_package, kept=True),
    # Not formats but exports all the same: the part of the robot others write (the driver
    # cuts it), a post_processing command (the driver runs it).
    Format("submodel", program.SubmodelExport, kept=True),
    Format("command", program.CommandExport),
)
FORMATS: dict[str, Format] = {f.name: f for f in _FORMATS}


def reader_of(path: Path) -> Format:
    """The format that reads `path`, by its suffix; a file of no known suffix is read as URDF
    (the inputs' default, as Phobos's)."""
    suffix = path.suffix.lower()
    return next((f for f in _FORMATS if f.read is not None and suffix in f.suffixes), FORMATS["urdf"])


def write(robot: Robot, export: Any, out: Path, sink: Sink) -> None:
    """Write `export` of `robot` into `out`, with its format's writer."""
    writer = FORMATS[export.type].write
    assert writer is not None, f"{export.type} exports are not written by a backend"
    writer(robot, export, out, sink)
