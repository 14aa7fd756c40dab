"""A frozen copy of backends/urdf_writer.py as it was before it became faster (issue 19):
tests/backends/test_writer_differential.py requires the new writer to write the same bytes for
every robot. A test fixture, never imported by mpc.

The original docstring: ir.Robot → canonical URDF text.

Canonical means: the same robot always gives the same bytes. Materials come first,
sorted by name; then the tree depth-first from the root, each joint followed by its
child link, siblings ordered by joint name (the order urdfdom and Pinocchio use);
then the opaque fragments in source order. Numbers use the shortest text that
reads back exactly. Attributes the source did not write are not written.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from mpc.backends import xml_escape
from mpc.backends.float_formats import Formats
from mpc.ir.fragments import Fragment
from mpc.ir.geometry import Attrs, Box, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.robot import Collision, Inertial, Joint, Link, Material, Pose, Robot, Visual
from mpc.ir.tree import depth_first

MeshNamer = Callable[[Mesh], str]


def fmt_float(x: float) -> str:
    """backends/xml.py's fmt_float before (frozen too)."""
    if x == 0.0:
        return "0"
    if math.isfinite(x) and x.is_integer() and abs(x) < 1e16:
        return str(int(x))
    return repr(x)


def fmt_floats(xs: tuple[float, ...] | list[float]) -> str:
    return " ".join(fmt_float(x) for x in xs)
IND = "  "


def _attrs(pairs: list[tuple[str, str | None]] | Attrs) -> str:
    return "".join([f' {k}="{xml_escape.attribute(v)}"' for k, v in pairs if v is not None])


class _Writer:
    def __init__(self, mesh_name: MeshNamer, formats: Formats | None = None) -> None:
        self.mesh_name, self.formats = mesh_name, formats
        self.out: list[str] = []
        # The text of each number and tuple written so far: a robot repeats many of them.
        self.texts: dict[float, str] = {}
        self.tuple_texts: dict[tuple[float, ...], str] = {}

    def num(self, x: float | None) -> str | None:
        if x is None:
            return None
        text = self.texts.get(x)
        if text is None:
            text = self.texts[x] = fmt_float(x)
        return text

    def nums(self, xs: tuple[float, ...]) -> str:
        if type(xs) is not tuple:  # a list: not hashable
            return fmt_floats(xs)
        text = self.tuple_texts.get(xs)
        if text is None:
            text = self.tuple_texts[xs] = fmt_floats(xs)
        return text

    def line(self, depth: int, text: str) -> None:
        self.out.append(IND * depth + text)

    def comments(self, depth: int, comments: tuple[str, ...]) -> None:
        for c in comments:
            self.line(depth, f"<!--{c}-->")

    def leaf(self, depth: int, tag: str, pairs: list[tuple[str, str | None]] | Attrs) -> None:
        if self.formats is not None:  # float_fmt_dict (backends/float_formats.py)
            pairs = [(k, self.formats(k, v)) for k, v in pairs]
        self.line(depth, f"<{tag}{_attrs(pairs)}/>")

    def fragment(self, depth: int, frag: Fragment) -> None:
        self.comments(depth, frag.comments)
        first, *rest = frag.xml.split("\n")
        self.line(depth, first)
        self.out.extend((IND * depth + ln) if ln else ln for ln in rest)

    def pose(self, depth: int, pose: Pose | None) -> None:
        if pose is None:
            return
        self.leaf(depth, "origin", [
            ("xyz", self.nums(pose.xyz) if pose.written[0] else None),
            ("rpy", self.nums(pose.rpy) if pose.written[1] else None),
        ])

    def geometry(self, depth: int, geometry: Geometry, attrs: Attrs) -> None:
        self.line(depth, f"<geometry{_attrs(attrs)}>")
        d = depth + 1
        match geometry:
            case Box():
                self.leaf(d, "box", [("size", self.nums(geometry.size)), *geometry.extra_attrs])
            case Cylinder():
                self.leaf(d, "cylinder", [("radius", self.num(geometry.radius)),
                                          ("length", self.num(geometry.length)),
                                          *geometry.extra_attrs])
            case Sphere():
                self.leaf(d, "sphere", [("radius", self.num(geometry.radius)),
                                        *geometry.extra_attrs])
            case Mesh():
                scale = self.nums(geometry.scale) if geometry.scale is not None else None
                self.leaf(d, "mesh", [("filename", self.mesh_name(geometry)), ("scale", scale),
                                      *geometry.extra_attrs])
        self.line(depth, "</geometry>")

    def material(self, depth: int, material: Material) -> None:
        self.comments(depth, material.comments)
        head = f"<material{_attrs([('name', material.name)])}"
        if material.rgba is None and material.texture is None:
            self.line(depth, head + "/>")
            return
        self.line(depth, head + ">")
        if material.rgba is not None:
            self.leaf(depth + 1, "color", [("rgba", self.nums(material.rgba))])
        if material.texture is not None:
            self.leaf(depth + 1, "texture", [("filename", material.texture or None)])
        self.line(depth, "</material>")

    def inertial(self, depth: int, inertial: Inertial) -> None:
        self.line(depth, "<inertial>")
        d = depth + 1
        self.pose(d, inertial.origin)
        self.leaf(d, "mass", [("value", self.num(inertial.mass))])
        i = inertial.inertia
        self.leaf(d, "inertia", [(k, self.num(getattr(i, k)))
                                 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")])
        for frag in inertial.extras:
            self.fragment(d, frag)
        self.line(depth, "</inertial>")

    def shape(self, depth: int, tag: str, item: Visual | Collision) -> None:
        self.line(depth, f"<{tag}{_attrs([('name', item.name), *item.extra_attrs])}>")
        d = depth + 1
        self.pose(d, item.origin)
        self.geometry(d, item.geometry, item.geometry_attrs)
        if isinstance(item, Visual) and item.material is not None:
            if item.inline_material is not None:
                self.material(d, item.inline_material)
            else:
                self.leaf(d, "material", [("name", item.material)])
        for frag in item.extras:
            self.fragment(d, frag)
        self.line(depth, f"</{tag}>")

    def link(self, depth: int, link: Link) -> None:
        self.comments(depth, link.comments)
        head = f"<link{_attrs([('name', link.name), *link.extra_attrs])}"
        body = link.inertial or link.visuals or link.collisions or link.extras
        if not body and not link.inner_comments:
            self.line(depth, head + "/>")
            return
        self.line(depth, head + ">")
        d = depth + 1
        self.comments(d, link.inner_comments)
        if link.inertial is not None:
            self.inertial(d, link.inertial)
        for visual in link.visuals:
            self.shape(d, "visual", visual)
        for collision in link.collisions:
            self.shape(d, "collision", collision)
        for frag in link.extras:
            self.fragment(d, frag)
        self.line(depth, "</link>")

    def joint(self, depth: int, joint: Joint) -> None:
        self.comments(depth, joint.comments)
        self.line(depth, f"<joint{_attrs([('name', joint.name), ('type', joint.type), *joint.extra_attrs])}>")
        d = depth + 1
        self.comments(d, joint.inner_comments)
        self.pose(d, joint.origin)
        self.leaf(d, "parent", [("link", joint.parent)])
        self.leaf(d, "child", [("link", joint.child)])
        if joint.axis is not None:
            self.leaf(d, "axis", [("xyz", self.nums(joint.axis))])
        if (c := joint.calibration) is not None:
            self.leaf(d, "calibration", [("rising", self.num(c.rising)), ("falling", self.num(c.falling)),
                                         ("reference_position", self.num(c.reference_position))])
        if (dyn := joint.dynamics) is not None:
            self.leaf(d, "dynamics", [("damping", self.num(dyn.damping)),
                                      ("friction", self.num(dyn.friction)), *dyn.extra_attrs])
        if (lim := joint.limit) is not None:
            self.leaf(d, "limit", [("lower", self.num(lim.lower)), ("upper", self.num(lim.upper)),
                                   ("effort", self.num(lim.effort)), ("velocity", self.num(lim.velocity)),
                                   *lim.extra_attrs])
        if (m := joint.mimic) is not None:
            self.leaf(d, "mimic", [("joint", m.joint), ("multiplier", self.num(m.multiplier)),
                                   ("offset", self.num(m.offset))])
        if (s := joint.safety_controller) is not None:
            self.leaf(d, "safety_controller", [
                ("soft_lower_limit", self.num(s.soft_lower_limit)),
                ("soft_upper_limit", self.num(s.soft_upper_limit)),
                ("k_position", self.num(s.k_position)), ("k_velocity", self.num(s.k_velocity))])
        for frag in joint.extras:
            self.fragment(d, frag)
        self.line(depth, "</joint>")


def to_string(robot: Robot, mesh_name: MeshNamer, formats: Formats | None = None) -> str:
    """The canonical URDF text of `robot`; `mesh_name` gives each mesh's filename; `formats`
    the number formats of `float_fmt_dict`, when given."""
    w = _Writer(mesh_name, formats)
    w.line(0, '<?xml version="1.0" encoding="utf-8"?>')
    w.comments(0, robot.header_comments)
    w.line(0, f"<robot{_attrs([('name', robot.name), *robot.extra_attrs])}>")
    for name in sorted(robot.materials):
        w.material(1, robot.materials[name])
    for joint, link in depth_first(robot):
        if joint is not None:
            w.joint(1, joint)
        w.link(1, robot.links[link])
    for frag in robot.fragments:
        w.fragment(1, frag)
    w.comments(1, robot.trailing_comments)
    w.line(0, "</robot>")
    return "\n".join(w.out) + "\n"
