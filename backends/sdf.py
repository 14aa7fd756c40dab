"""ir.Robot → canonical SDFormat (1.6, 1.7 or 1.9): one `<model>`, plus Gazebo's model.config.

Links and joints come depth-first as in the URDF writer, numbers use `fmt_float`, and
the same robot always gives the same bytes. Every link pose is in the model frame (at
q = 0); each joint frame is its child link's frame, so joints carry no pose and their
axis is written in the joint frame, exactly as the IR holds it. What SDF cannot hold
or mpc does not translate (mimic, floating and planar joints, fragments, extras,
motors, sensors, cut joints, …) is left out and named in one W0500 warning.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterator
from pathlib import Path

from mpc.backends import holds, meshes, xml_escape
from mpc.backends.float_formats import SDF_KEYS, Formats
from mpc.backends.mesh_paths import variants
from mpc.backends.sdf_reader import read
from mpc.backends.xml import fmt_float, fmt_floats, write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.core.span import Span
from mpc.ir.extras import CutJoint, Sensor
from mpc.ir.geometry import Box, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.kinematics import links_in_root, matrix_pose
from mpc.ir.program import SdfExport
from mpc.ir.robot import Collision, Inertia, Inertial, Joint, Link, Material, Pose, Robot, Visual
from mpc.ir.tree import depth_first

__all__ = ["emit", "read", "sdf_names", "to_string"]

MeshNamer = Callable[[Mesh], str]
IND = "  "
WORLD = "world"  # SDF's name for the world frame, reserved as a link name
UNBOUNDED = 1e16  # the position limit SDF uses for "no limit" (its default, and sdformat's)
_SKIPPED = ("floating", "planar")  # URDF joint types SDF has no joint for
# The IR's single-link sensors SDF has, by their SDF type (Joint6DOF goes into its joint).
LINK_SENSORS = {"IMU": "imu", "CameraSensor": "camera", "RotatingRaySensor": "gpu_lidar", "GPS": "navsat"}
# A link without <inertial> weighs 1 kg in SDF; in URDF it is massless.
_MASSLESS = Inertial(mass=0.0, inertia=Inertia(ixx=0.0, ixy=0.0, ixz=0.0, iyy=0.0, iyz=0.0, izz=0.0))


def _attr(value: str) -> str:
    return xml_escape.attribute(value)


def _is_empty(link: Link) -> bool:
    return link.inertial is None and not link.visuals and not link.collisions


def sdf_names(robot: Robot) -> tuple[dict[str, str], dict[str, str]]:
    """The names links and joints get in SDF: (links, joints), each old → new.

    SDF links, joints and frames share one namespace and `world` names the world frame:
    an empty root link `world` becomes the world frame itself (its joints attach the model
    to the world), another link `world` becomes `world_link`, and a joint named like a
    link gets `_joint` appended, as sdformat's own URDF parser does.
    """
    links = {name: name for name in robot.links}
    if WORLD in links and not (robot.root == WORLD and _is_empty(robot.links[WORLD])):
        links[WORLD] = _unique(WORLD, "_link", set(robot.links) | set(robot.joints))
    link_names = set(links.values())
    taken = link_names | set(robot.joints)
    joints = {}
    for name in robot.joints:
        joints[name] = name if name not in link_names else _unique(name, "_joint", taken)
        taken.add(joints[name])
    return links, joints


def _unique(name: str, suffix: str, taken: set[str]) -> str:
    new = name + suffix
    while new in taken:
        new += suffix
    return new


def left_out(robot: Robot, cut_joints: bool = False) -> list[str]:
    """What the robot holds that this writer does not write to SDF, for one W0500 (the table
    `CANNOT_HOLD`, read by backends/holds.py).

    cut_joints: whether the loop-closure joints are written (`include_cut_joints`).
    """
    return holds.left_out(robot, CANNOT_HOLD, cut_joints=cut_joints)


def _joints(robot: Robot) -> list[Joint]:
    return sorted(robot.joints.values(), key=lambda j: j.name)


def _skipped_joints(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for j in _joints(robot):
        if j.type in _SKIPPED:
            yield holds.Named(f"{j.type} joint '{j.name}' (SDF has none: link '{j.child}' "
                              "is written free)"), 1


def _mimics(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    if mimics := [j.name for j in _joints(robot) if j.mimic is not None]:
        yield holds.Named("the mimic of joint" + "s" * (len(mimics) > 1) + " "
                          + ", ".join(f"'{m}'" for m in mimics)), 1


def _untyped_sensor(sensor: Sensor) -> bool:
    return sensor.type not in (*LINK_SENSORS, "Joint6DOF") or (not sensor.link and not sensor.joint)


def _fragments(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for f in robot.fragments:
        yield holds.noun(f"<{f.tag}> fragment"), 1


def _inertial_extras(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    """Link by link: the extra elements of its inertial, then its collisions' bitmasks."""
    for lk in robot.links.values():
        for f in lk.inertial.extras if lk.inertial else ():
            yield holds.noun("inertial", f"<{f.tag}> in "), 1
        yield holds.noun("collision bitmask"), sum(c.bitmask is not None for c in lk.collisions)


def _element_extras(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    """The joints', links', visuals' and collisions' extra elements, annotations and attributes."""
    elements: list[tuple[str, Link | Joint | Visual | Collision]] = [("joint", j) for j in _joints(robot)]
    for lk in robot.links.values():
        elements += [("link", lk)] + [("visual", v) for v in lk.visuals]
        elements += [("collision", c) for c in lk.collisions]
    for kind, el in elements:
        for f in el.extras:
            yield holds.noun(kind, f"<{f.tag}> in "), 1
        yield holds.noun(kind, "annotations of "), int(bool(el.annotations))
        attrs = list(el.extra_attrs)
        if isinstance(el, Visual | Collision):
            for a, _ in (*el.geometry_attrs, *el.geometry.extra_attrs):
                yield holds.noun(kind, f"attribute '{a}' of the geometry in "), 1
        elif isinstance(el, Joint):
            attrs += [a for part in (el.limit, el.dynamics) if part is not None for a in part.extra_attrs]
        for name, _ in attrs:
            yield holds.noun(kind, f"attribute '{name}' of "), 1


def _material_details(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for m in _used_materials(robot):
        yield holds.noun("material texture"), int(m.texture is not None or m.normal_texture is not None)
        yield holds.noun("material shininess"), int(m.shininess is not None)
        yield holds.noun("material", "annotations of "), int(bool(m.annotations))


# What SDF cannot hold or this writer does not translate, in the order W0500 names it.
CANNOT_HOLD: tuple[holds.Tally, ...] = (
    _skipped_joints,
    _mimics,
    holds.count(holds.noun("motor"), lambda r, o: len(r.motors)),
    holds.count(holds.Counted("sensor SDF has no type for", "sensors SDF has no type for"),
                lambda r, o: sum(map(_untyped_sensor, r.sensors.values()))),
    holds.count(holds.noun("named pose"), lambda r, o: len(r.poses)),
    holds.count(holds.noun("loop-closure joint"), lambda r, o: 0 if o["cut_joints"] else len(r.cut_joints)),
    holds.count(holds.noun("submechanism"), lambda r, o: len(r.submechanisms)),
    holds.count(holds.Counted("annotation category", "annotation categories"),
                lambda r, o: len(r.annotations)),
    holds.count(holds.noun("joint calibration"), lambda r, o: sum(j.calibration is not None
                                                                   for j in r.joints.values())),
    holds.count(holds.noun("joint safety controller"), lambda r, o: sum(j.safety_controller is not None
                                                                         for j in r.joints.values())),
    _fragments,
    _inertial_extras,
    _element_extras,
    _material_details,
    holds.named(holds.Named("the submechanisms file"), lambda r, o: bool(r.submechanisms_file)),
)


def _used_materials(robot: Robot) -> list[Material]:
    found = {}
    for lk in robot.links.values():
        for v in lk.visuals:
            m = _material(robot, v)
            if m is not None:
                found[id(m)] = m
    return list(found.values())


def _material(robot: Robot, visual: Visual) -> Material | None:
    if visual.inline_material is not None:
        return visual.inline_material
    return robot.materials.get(visual.material) if visual.material is not None else None


def warn(robot: Robot, span: Span, sink: Sink, version: str = "1.9", cut_joints: bool = False) -> None:
    """Report, in one W0500 each, what the SDF leaves out and which names it changes."""
    missing = left_out(robot, cut_joints)
    if missing:
        sink.warning(span, "W0500", f"the SDF leaves out what SDFormat {version} cannot hold or mpc "
                     "does not translate: " + "; ".join(missing))
    links, joints = sdf_names(robot)
    renamed = [f"{kind} '{a}' → '{b}'" for kind, table in (("link", links), ("joint", joints))
               for a, b in table.items() if a != b]
    if renamed:
        sink.warning(span, "W0501", "the SDF renames what SDFormat forbids (links, joints and "
                     "frames share one namespace; 'world' is reserved): " + ", ".join(renamed))


class _Writer:
    def __init__(self, robot: Robot, mesh_name: MeshNamer, formats: Formats | None = None) -> None:
        self.robot, self.mesh_name, self.formats = robot, mesh_name, formats
        self.links, self.joints = sdf_names(robot)
        self.X_R = links_in_root(robot)  # SDF poses are in the model frame
        self.out: list[str] = []

    def line(self, depth: int, text: str) -> None:
        self.out.append(IND * depth + text)

    def comments(self, depth: int, comments: tuple[str, ...]) -> None:
        for c in comments:
            self.line(depth, f"<!--{c}-->")

    def leaf(self, depth: int, tag: str, value: str) -> None:
        if self.formats is not None:  # float_fmt_dict (backends/float_formats.py)
            value = self.formats(tag, value) or value
        self.line(depth, f"<{tag}>{xml_escape.text(value)}</{tag}>")

    def pose(self, depth: int, pose: Pose | None, always: bool = False) -> None:
        if pose is None or (not always and pose.xyz == (0, 0, 0) and pose.rpy == (0, 0, 0)):
            return
        self.leaf(depth, "pose", fmt_floats(pose.xyz + pose.rpy))

    def _emit_link(self, depth: int, link: Link) -> None:
        self.comments(depth, link.comments)
        self.line(depth, f'<link name="{_attr(self.links[link.name])}">')
        d = depth + 1
        self.comments(d, link.inner_comments)
        self.pose(d, matrix_pose(self.X_R[link.name]), always=True)
        self._emit_inertial(d, link.inertial or _MASSLESS)
        for kind, items in (("visual", link.visuals), ("collision", link.collisions)):
            used: set[str] = set()
            for i, item in enumerate(items):
                # sdformat trims a name: one of spaces only (a tab in an SDF input, which XML reads
                # as a space) is read as none, and refused; it gets the name of an unnamed shape
                name = (item.name or "").strip() or (f"{link.name}_{kind}" + (f"_{i}" if i else ""))
                name = _unique(name, f"_{i}", used) if name in used else name
                used.add(name)
                self._emit_shape(d, kind, name, item)
        for sensor in sorted(self.robot.sensors.values(), key=lambda x: x.name):
            if sensor.link == link.name and sensor.type in LINK_SENSORS:
                self._emit_sensor(d, sensor, LINK_SENSORS[sensor.type])
        self.line(depth, "</link>")

    def _emit_sensor(self, depth: int, sensor: Sensor, kind: str) -> None:
        """A sensor as SDF has it: its type and pose; type-specific settings are left to
        SDF's defaults (the IR keeps them as annotations, for SMURF)."""
        self.line(depth, f'<sensor name="{_attr(sensor.name)}" type="{kind}">')
        xyz = sensor.position_offset or (0.0, 0.0, 0.0)
        rpy = sensor.orientation_offset if sensor.orientation_offset and len(sensor.orientation_offset) == 3 \
            else (0.0, 0.0, 0.0)
        self.pose(depth + 1, Pose(tuple(xyz), tuple(rpy)))  # type: ignore[arg-type]
        if kind == "camera":
            self.line(depth + 1, "<camera/>")
        self.line(depth, "</sensor>")

    def _emit_inertial(self, depth: int, inertial: Inertial) -> None:
        self.line(depth, "<inertial>")
        d = depth + 1
        self.pose(d, inertial.origin)
        self.leaf(d, "mass", fmt_float(inertial.mass))
        self.line(d, "<inertia>")
        for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
            self.leaf(d + 1, k, fmt_float(getattr(inertial.inertia, k)))
        self.line(d, "</inertia>")
        self.line(depth, "</inertial>")

    def _emit_shape(self, depth: int, kind: str, name: str, item: Visual | Collision) -> None:
        self.line(depth, f'<{kind} name="{_attr(name)}">')
        d = depth + 1
        self.pose(d, item.origin)
        self._emit_geometry(d, item.geometry)
        material = _material(self.robot, item) if isinstance(item, Visual) else None
        if material is not None:
            if material.transparency is not None:
                self.leaf(d, "transparency", fmt_float(material.transparency))
            self._emit_material(d, material)
        self.line(depth, f"</{kind}>")

    def _emit_geometry(self, depth: int, geometry: Geometry) -> None:
        self.line(depth, "<geometry>")
        d = depth + 1
        match geometry:
            case Box():
                self.line(d, "<box>")
                self.leaf(d + 1, "size", fmt_floats(geometry.size))
                self.line(d, "</box>")
            case Cylinder():
                self.line(d, "<cylinder>")
                self.leaf(d + 1, "radius", fmt_float(geometry.radius))
                self.leaf(d + 1, "length", fmt_float(geometry.length))
                self.line(d, "</cylinder>")
            case Sphere():
                self.line(d, "<sphere>")
                self.leaf(d + 1, "radius", fmt_float(geometry.radius))
                self.line(d, "</sphere>")
            case Mesh():
                self.line(d, "<mesh>")
                self.leaf(d + 1, "uri", self.mesh_name(geometry))
                if geometry.scale is not None:
                    self.leaf(d + 1, "scale", fmt_floats(geometry.scale))
                self.line(d, "</mesh>")
        self.line(depth, "</geometry>")

    def _emit_material(self, depth: int, material: Material) -> None:
        colours = [("ambient", material.ambient), ("diffuse", material.rgba),
                   ("specular", material.specular), ("emissive", material.emissive)]
        colours = [(tag, c) for tag, c in colours if c is not None]
        if not colours:
            return
        self.line(depth, "<material>")
        for tag, colour in colours:
            # SDF colours are "r g b a"; an rgb colour is opaque.
            self.leaf(depth + 1, tag, fmt_floats(tuple(colour) + (1.0,) * (4 - len(colour))))
        self.line(depth, "</material>")

    def _emit_joint(self, depth: int, joint: Joint) -> None:
        self.comments(depth, joint.comments)
        jtype = "revolute" if joint.type == "continuous" else joint.type
        self.line(depth, f'<joint name="{_attr(self.joints[joint.name])}" type="{jtype}">')
        d = depth + 1
        self.comments(d, joint.inner_comments)
        self.leaf(d, "parent", self.links[joint.parent])
        self.leaf(d, "child", self.links[joint.child])
        if joint.type != "fixed":
            self._emit_axis(d, joint)
        for sensor in sorted(self.robot.sensors.values(), key=lambda x: x.name):
            if sensor.type == "Joint6DOF" and (sensor.joint == joint.name or sensor.link == joint.child):
                self.line(d, f'<sensor name="{_attr(sensor.name)}" type="force_torque"/>')
        self.line(depth, "</joint>")

    def _emit_cut_joint(self, depth: int, cut: CutJoint) -> None:
        """A loop closure, in the child's frame (where the tree puts it at q = 0). A fixed or
        ball closure needs no axis; another type takes its one constraint axis."""
        kind = cut.type if cut.type in ("fixed", "ball", "revolute", "prismatic") else "fixed"
        self.line(depth, f'<joint name="{_attr(cut.name)}" type="{kind}">')
        self.leaf(depth + 1, "parent", self.links.get(cut.parent, cut.parent))
        self.leaf(depth + 1, "child", self.links.get(cut.child, cut.child))
        # Where the closure sits on the child, when it is not the child's origin (an SDF input
        # says so; the reader keeps it as `joint_origin`): a ball joint elsewhere is another loop.
        jo = cut.annotations.get("joint_origin")
        if isinstance(jo, dict):
            self.pose(depth + 1, Pose(tuple(jo.get("xyz", (0.0, 0.0, 0.0))),  # type: ignore[arg-type]
                                      tuple(jo.get("rpy", (0.0, 0.0, 0.0)))))  # type: ignore[arg-type]
        if kind in ("revolute", "prismatic"):
            axis = cut.constraint_axes[0][1] if cut.constraint_axes else (0.0, 0.0, 1.0)
            self.line(depth + 1, "<axis>")
            self.leaf(depth + 2, "xyz", fmt_floats(axis))
            self.line(depth + 1, "</axis>")
        self.line(depth, "</joint>")

    def _emit_axis(self, depth: int, joint: Joint) -> None:
        self.line(depth, "<axis>")
        d = depth + 1
        # No expressed_in: the axis is in the joint frame, which is the child link's frame
        # here, as in URDF. SDF's default axis is 0 0 1, URDF's 1 0 0.
        self.leaf(d, "xyz", fmt_floats(joint.axis if joint.axis is not None else (1.0, 0.0, 0.0)))
        dyn = joint.dynamics
        if dyn is not None and (dyn.damping is not None or dyn.friction is not None):
            self.line(d, "<dynamics>")
            for k in ("damping", "friction"):
                if getattr(dyn, k) is not None:
                    self.leaf(d + 1, k, fmt_float(getattr(dyn, k)))
            self.line(d, "</dynamics>")
        lim = joint.limit
        if joint.type == "continuous":
            lower, upper = -UNBOUNDED, UNBOUNDED
        else:  # URDF's lower and upper default to 0
            lower = lim.lower if lim is not None and lim.lower is not None else 0.0
            upper = lim.upper if lim is not None and lim.upper is not None else 0.0
        self.line(d, "<limit>")
        self.leaf(d + 1, "lower", fmt_float(lower))
        self.leaf(d + 1, "upper", fmt_float(upper))
        for k in ("effort", "velocity"):
            if lim is not None and getattr(lim, k) is not None:
                self.leaf(d + 1, k, fmt_float(getattr(lim, k)))
        self.line(d, "</limit>")
        self.line(depth, "</axis>")


def to_string(robot: Robot, mesh_name: MeshNamer, version: str = "1.9",
              sink: Sink | None = None, cut_joints: bool = False, formats: Formats | None = None) -> str:
    """The canonical SDF text of `robot`; `mesh_name` gives each mesh's uri.

    With a sink, what the SDF leaves out or renames is reported there (W0500).
    cut_joints: also write the loop-closure joints (SDF allows loops).
    """
    if sink is not None:
        warn(robot, robot.span or Span.of_file(robot.name), sink, version, cut_joints)
    w = _Writer(robot, mesh_name, formats)
    w.line(0, '<?xml version="1.0" encoding="utf-8"?>')
    w.comments(0, robot.header_comments)
    w.line(0, f'<sdf version="{version}">')
    w.line(1, f'<model name="{_attr(robot.name)}">')
    for joint, link in depth_first(robot):
        if joint is not None and joint.type not in _SKIPPED:
            w._emit_joint(2, joint)
        if w.links[link] != WORLD:
            w._emit_link(2, robot.links[link])
    if cut_joints:
        for name in sorted(robot.cut_joints):
            w._emit_cut_joint(2, robot.cut_joints[name])
    w.comments(2, robot.trailing_comments)
    w.line(1, "</model>")
    w.line(0, "</sdf>")
    return "\n".join(w.out) + "\n"


def model_config(robot: Robot, version: str = "1.9") -> str:
    """Gazebo's model.config for the model: name, version, the SDF file, a description."""
    name = xml_escape.text(robot.name)
    return (f'<?xml version="1.0" encoding="utf-8"?>\n<model>\n{IND}<name>{name}</name>\n'
            f'{IND}<version>1.0</version>\n{IND}<sdf version="{version}">{name}.sdf</sdf>\n'
            f"{IND}<description>The robot '{name}', written by mpc.</description>\n</model>\n")


HINT_CORRECT = "set `correct_inertials: true` on the export to make it physical, or fix its inertial"


def check_inertials(robot: Robot, sink: Sink, span: Span, only: Collection[str] | None = None) -> bool:
    """Report (E0504) each link whose inertial SDFormat refuses ("A link named … has invalid
    inertia", ir/physical.py `sdformat_problems`), at the link; whether there was none.
    only: the links to report (`mpc check`: those the finished robot keeps)."""
    from mpc.ir.physical import sdformat_problems

    ok = True
    for name, link in robot.links.items():
        if only is not None and name not in only:
            continue
        problems = sdformat_problems(link.inertial) if link.inertial is not None else []
        if problems:
            sink.error(link.span or span, "E0504", f"link '{name}' has an inertial SDFormat refuses: "
                       f"{'; '.join(problems)}", hint=HINT_CORRECT,
                       notes=((span, "the sdf export that would write it"),) if link.span else ())
            ok = False
    return ok


def emit(robot: Robot, export: SdfExport, out: Path, sink: Sink) -> None:
    """Write `out/sdf/<filename or robot.name>.sdf` and `out/sdf/model.config`, meshes under
    `out/meshes/`; nothing with an inertial SDFormat refuses (E0504)."""
    warn(robot, export.span, sink, export.version, export.include_cut_joints)
    if not check_inertials(robot, sink, export.span):
        return
    prepared = meshes.for_export(robot, export, out, sink)
    if prepared is None:
        return
    robot, files = prepared
    formats = Formats(export.float_formats, SDF_KEYS) if export.float_formats else None
    # Relative to the .sdf file: sdformat accepts it, and Gazebo resolves it from the
    # file's folder; model:// would need the meshes inside the model folder (out/sdf).
    # Or package:// paths (ros_pathes), which ROS's Gazebo resolves (backends/mesh_paths.py).
    for suffix, prefix in variants(export):
        text = to_string(robot, meshes.namer(files, prefix), export.version,
                         cut_joints=export.include_cut_joints, formats=formats)
        write_path(confined(out, "sdf", f"{export.filename or robot.name}{suffix}.sdf"), text)
    write_path(confined(out, "sdf", "model.config"), model_config(robot, export.version))
