"""ir.Robot → OpenUSD (`type: usd`), built with usd-core: `<out>/usd/<filename>.usda`.

Two layouts, the same prims (backends/usd_stage.py authors them):
- `layered` (the default), as REP 158 and NVIDIA's asset structure lay a robot out: the
  interface layer `usd/<filename>.usda` (stage metadata, the default prim, its payload) and
  `usd/<filename>_payload/`: `contents.usda`, which sublayers `physics.usda`,
  `materials.usda` and `geometry.usdc` (strongest first; the meshes' points in USD's binary
  crate, the rest as text). A consumer that needs no physics or no looks can leave a layer out.
- `single`: everything in `usd/<filename>.usda`.

Every layer has metres (metersPerUnit 1), kilograms (kilogramsPerUnit 1), Z up
and its default prim; the same robot gives the same bytes. Meshes are read through the mesh
cache (backends/usd_meshes.py) and held in the geometry layer; no mesh files are written.
What USD (with UsdPhysics and Newton's mimic schema) cannot hold is named in one W0500.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.backends import holds
from mpc.backends.usd_kinds import ONE_DOF, mimic_written, written_cut
from mpc.core.diagnostics import Sink
from mpc.core.files import confined, write_atomic
from mpc.ir.geometry import Mesh
from mpc.ir.program import UsdExport
from mpc.ir.robot import Inertial, Robot

if TYPE_CHECKING:
    from mpc.backends.usd_pxr import Layer

__all__ = ["CANNOT_HOLD", "PARTS", "emit", "layers_text", "left_out"]

# The payload's sublayers, strongest first, with their file names: the meshes' points in USD's
# binary crate (a tenth of the text's size, written in a fiftieth of its time; the same bytes
# for the same layer), the rest as text, which reviews well.
PARTS = (("physics", "physics.usda"), ("materials", "materials.usda"), ("geometry", "geometry.usdc"))


def _cut_left(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for c in sorted(robot.cut_joints.values(), key=lambda c: c.name):
        if not written_cut(c):
            yield holds.Named(f"{c.type} cut joint '{c.name}' (no UsdPhysics joint holds it)"), 1


def _mimic_left(robot: Robot, options: holds.Options) -> int:
    return sum(j.mimic is not None and not mimic_written(j, robot.joints.get(j.mimic.joint))
               for j in robot.joints.values())


def _element_tags(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    shapes = [s for lk in robot.links.values() for s in (*lk.visuals, *lk.collisions)]
    inertials = [lk.inertial for lk in robot.links.values() if lk.inertial is not None]
    elements = (*robot.links.values(), *robot.joints.values(), *shapes, *inertials)
    for tag, n in sorted(Counter(f.tag for f in (*robot.fragments,
                                                  *(f for e in elements for f in e.extras))).items()):
        yield holds.noun(f"<{tag}> element"), n


def _beyond_colour(robot: Robot, options: holds.Options) -> int:
    inline = [v.inline_material for lk in robot.links.values() for v in lk.visuals]
    return sum(m.texture is not None or m.normal_texture is not None or any(
        getattr(m, k) is not None for k in ("ambient", "specular", "shininess", "transparency"))
        for m in (*robot.materials.values(), *(m for m in inline if m is not None)))


def _no_mass(inertial: Inertial | None) -> bool:
    """No inertial, mass 0, or a zero inertia tensor: what UsdPhysics reads as "not given"."""
    if inertial is None or inertial.mass == 0:
        return True
    i = inertial.inertia
    return not any((i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz))


_NO_MASS = "massless or point-mass"
_COMPUTED = " with collision shapes (UsdPhysics reads mass or inertia 0 as \"compute it from the shapes\")"
_C = holds.Counted
# What the USD cannot hold, in the order W0500 names it.
CANNOT_HOLD: tuple[holds.Tally, ...] = (
    holds.count(_C("sensor", "sensors"), lambda r, o: len(r.sensors)),
    holds.count(_C("pose", "poses"), lambda r, o: len(r.poses)),
    holds.count(_C("submechanism", "submechanisms"), lambda r, o: len(r.submechanisms)),
    holds.count(_C("annotation category", "annotation categories"), lambda r, o: len(r.annotations)),
    holds.count(_C(f"{_NO_MASS} link{_COMPUTED}", f"{_NO_MASS} links{_COMPUTED}"), lambda r, o: sum(
        bool(lk.collisions) and _no_mass(lk.inertial) for lk in r.links.values())),
    holds.count(_C("planar joint", "planar joints"), lambda r, o: sum(
        j.type == "planar" for j in r.joints.values())),
    holds.count(_C("velocity limit or dynamics of a joint without one degree of freedom",
                   "velocity limits or dynamics of joints without one degree of freedom"), lambda r, o: sum(
        j.type not in ONE_DOF and ((j.limit is not None and j.limit.velocity is not None) or (
            j.dynamics is not None and bool(j.dynamics.damping or j.dynamics.friction)))
        for j in r.joints.values())),
    holds.count(_C("joint calibration", "joint calibrations"), lambda r, o: sum(
        j.calibration is not None for j in r.joints.values())),
    holds.count(_C("safety controller", "safety controllers"), lambda r, o: sum(
        j.safety_controller is not None for j in r.joints.values())),
    holds.count(_C("mimic of or by a joint of another kind or without one degree of freedom",
                   "mimics of or by joints of another kind or without one degree of freedom"), _mimic_left),
    holds.count(_C("motor of a joint without one degree of freedom", "motors of joints without one degree "
                   "of freedom"), lambda r, o: sum(
        r.joints.get(m.joint) is None or r.joints[m.joint].type not in ONE_DOF
        for m in r.motors.values())),
    holds.count(_C("material texture or property beyond colour", "material textures or properties beyond "
                   "colour"), _beyond_colour),
    _cut_left,
    _element_tags,
    holds.named(holds.Named("the submechanisms file"), lambda r, o: bool(r.submechanisms_file)),
)


def left_out(robot: Robot) -> list[str]:
    """What the robot holds that this USD does not (the table `CANNOT_HOLD`)."""
    return holds.left_out(robot, CANNOT_HOLD)


def layers_text(robot: Robot, layout: str, triangles: object, payload_folder: str) -> dict[str, str | bytes]:
    """The content of each layer (USDA text, or a crate's bytes), by its path relative to
    `usd/` ("" for the file the export names) and, for the layered layout, the payload's layers
    in `payload_folder`."""
    from mpc.backends.usd_pxr import Sdf
    from mpc.backends.usd_stage import Author, Layers

    if layout == "single":
        one = Sdf.Layer.CreateAnonymous("single.usda")
        parts = Layers(one, one, one)
    else:
        parts = Layers(*(Sdf.Layer.CreateAnonymous(f"{p}.usda")
                         for p in ("geometry", "materials", "physics")))
    author = Author(robot, parts, triangles)  # type: ignore[arg-type]
    author.geometry()
    author.materials_part()
    author.physics()
    root = author.root.name
    if layout == "single":
        _metadata(parts.geometry, root)
        return {"": parts.geometry.ExportToString()}
    out: dict[str, str | bytes] = {}
    for name, file in PARTS:
        layer = getattr(parts, name)
        _metadata(layer, root)
        out[f"{payload_folder}/{file}"] = _crate(layer) if file.endswith(".usdc") else layer.ExportToString()
    contents = Sdf.Layer.CreateAnonymous("contents.usda")
    _metadata(contents, root)
    contents.subLayerPaths = [f"./{file}" for _, file in PARTS]
    out[f"{payload_folder}/contents.usda"] = contents.ExportToString()
    interface = Sdf.Layer.CreateAnonymous("interface.usda")
    _metadata(interface, root)
    prim = Sdf.CreatePrimInLayer(interface, Sdf.Path("/" + root))
    prim.specifier = Sdf.SpecifierDef
    prim.typeName = "Xform"
    prim.kind = "component"
    prim.payloadList.Prepend(Sdf.Payload(f"./{payload_folder}/contents.usda"))
    out[""] = interface.ExportToString()
    return out


def _crate(layer: Layer) -> bytes:
    """The layer in USD's binary crate format (usd-core writes it only to a file)."""
    import tempfile


    with tempfile.TemporaryDirectory(prefix="mpc-usdc-") as folder:
        path = f"{folder}/layer.usdc"
        if not layer.Export(path):
            raise OSError(f"usd-core could not write the crate file '{path}'")
        with open(path, "rb") as crate:
            return crate.read()


def _metadata(layer: Layer, root: str) -> None:
    """Metres, kilograms, Z up and the default prim, on a layer."""
    layer.defaultPrim = root
    info = dict(layer.pseudoRoot.GetInfo("customLayerData") or {})
    layer.pseudoRoot.SetInfo("metersPerUnit", 1.0)  # UsdGeom's and UsdPhysics's layer metadata
    layer.pseudoRoot.SetInfo("kilogramsPerUnit", 1.0)
    layer.pseudoRoot.SetInfo("upAxis", "Z")
    if info:
        layer.customLayerData = info


FLOAT_MAX = 3.4028234663852886e38  # the largest 32-bit float: UsdPhysics's masses, moments and points
# A number that is not finite as usd-core writes it in text: a word inf, -inf or nan.
_NOT_FINITE = re.compile(r"[\s(\[,=]-?(?:inf|nan)(?=[\s)\],])")


def _beyond_floats(inertial: Inertial) -> str | None:
    """Why UsdPhysics's 32-bit floats cannot hold the inertial (a mass, a moment or a centre of
    mass beyond ±3.4e38 becomes infinite in them), or None."""
    from mpc.backends.mjcf import principal

    xyz = inertial.origin.xyz if inertial.origin is not None else (0.0, 0.0, 0.0)
    if any(abs(x) > FLOAT_MAX for x in (inertial.mass, *xyz, *principal(inertial)[0])):
        return ("its mass, principal moments or centre of mass hold a number beyond ±3.4e38, the largest "
                "of the 32-bit floats UsdPhysics keeps them in")
    return None


def emit(robot: Robot, export: UsdExport, out: Path, sink: Sink) -> None:
    """Write `out/usd/<filename or robot.name>.usda` (and its payload's layers, `layered`)."""
    from mpc.backends import meshes, usd_meshes
    from mpc.backends.dae_colours import coloured
    from mpc.backends.mjcf import unusable_inertial
    from mpc.backends.smurf_forms import named_shapes

    unusable = [(name, problem) for name, link in robot.links.items() if link.inertial is not None and (
        problem := unusable_inertial(link.inertial) or _beyond_floats(link.inertial)) is not None]
    for name, problem in unusable:
        sink.error(robot.links[name].span or export.span, "E0587", f"link '{name}' has an inertial "
                   f"UsdPhysics cannot hold: {problem}; no USD is written", hint="fix its <inertial>")
    if unusable:
        return
    missing = left_out(robot)
    if missing:
        sink.warning(export.span, "W0500", "the USD leaves out what it cannot hold: " + ", ".join(missing))
    robot = coloured(named_shapes(robot))
    found = usd_meshes.triangles(robot, sink, export.span)
    if found is None:
        return
    name = export.filename or robot.name

    def triangles(mesh: Mesh) -> usd_meshes.Triangles:
        return found[meshes.key(mesh)]

    texts = layers_text(robot, export.layout, triangles, f"{name}_payload")
    for rel, text in texts.items():  # a crate layer (bytes) holds the meshes, checked as read
        if isinstance(text, str) and (found_at := _NOT_FINITE.search(text)) is not None:
            line = text.count("\n", 0, found_at.start()) + 1
            usd_meshes.not_finite(sink, export.span, f"'{found_at[0].strip()}' in line {line} of "
                                  f"'{rel or name + '.usda'}'")
            return
    for rel, text in texts.items():
        path = confined(out, "usd", f"{name}.usda") if not rel else confined(out, "usd", rel)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, text)
