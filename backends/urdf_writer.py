"""ir.Robot → canonical URDF text.

Canonical means: the same robot always gives the same bytes. Materials come first,
sorted by name; then the tree depth-first from the root, each joint followed by its
child link, siblings ordered by joint name (the order urdfdom and Pinocchio use);
then the opaque fragments in source order. Numbers use the shortest text that
reads back exactly. Attributes the source did not write are not written.
"""

from __future__ import annotations

from collections.abc import Callable

from mpc.backends import xml_escape
from mpc.backends.float_formats import Formats
from mpc.backends.xml import fmt_float, fmt_floats
from mpc.ir.fragments import Fragment
from mpc.ir.geometry import Attrs, Box, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.robot import Collision, Inertial, Joint, Link, Material, Pose, Robot, Visual
from mpc.ir.tree import depth_first

MeshNamer = Callable[[Mesh], str]
IND = "  "
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
Pairs = list[tuple[str, str | None]] | Attrs


class _Writer:
    """The lines of one URDF text. A number's text needs no escaping, so elements of numbers
    alone are written without `attrs` when no float formats apply (`numbers`): most lines."""

    def __init__(self, mesh_name: MeshNamer, formats: Formats | None = None) -> None:
        self.mesh_name, self.formats = mesh_name, formats
        self.out: list[str] = []
        # The text of each number, tuple and attribute value written so far: a robot repeats
        # many of them.
        self.texts: dict[float, str] = {}
        self.tuple_texts: dict[tuple[float, ...], str] = {}
        self.escaped: dict[str, str] = {}

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

    def escape(self, value: str) -> str:
        safe = self.escaped.get(value)
        if safe is None:
            safe = self.escaped[value] = xml_escape.attribute(value)
        return safe

    def attrs(self, pairs: Pairs) -> str:
        """` key="value"` for each pair whose value is not None, the value escaped."""
        escaped = self.escaped
        text = ""
        for key, value in pairs:
            if value is not None:
                safe = escaped.get(value)
                if safe is None:
                    safe = escaped[value] = xml_escape.attribute(value)
                text += f' {key}="{safe}"'
        return text

    def comments(self, ind: str, comments: tuple[str, ...]) -> None:
        for c in comments:
            self.out.append(f"{ind}<!--{c}-->")

    def leaf(self, ind: str, tag: str, pairs: Pairs) -> None:
        if self.formats is not None:  # float_fmt_dict (backends/float_formats.py)
            pairs = [(k, self.formats(k, v)) for k, v in pairs]
        self.out.append(f"{ind}<{tag}{self.attrs(pairs)}/>")

    def numbers(self, ind: str, tag: str, keys: tuple[str, ...], values: tuple[float | None, ...],
                extra: Attrs = ()) -> None:
        """A leaf of the numbers `values` (None: not written) and then the attributes `extra`."""
        if self.formats is not None or extra:
            self.leaf(ind, tag, [*zip(keys, map(self.num, values), strict=True), *extra])
            return
        text = ""
        for key, value in zip(keys, values, strict=True):
            if value is not None:
                text += f' {key}="{self.num(value)}"'
        self.out.append(f"{ind}<{tag}{text}/>")

    def fragment(self, ind: str, frag: Fragment) -> None:
        self.comments(ind, frag.comments)
        xml = frag.xml
        if "\n\n" not in xml and xml[-1:] != "\n":  # every line indented: no empty one
            self.out.append(ind + xml.replace("\n", "\n" + ind))
            return
        first, *rest = xml.split("\n")
        self.out.append(ind + first)
        self.out.extend((ind + ln) if ln else ln for ln in rest)

    def pose(self, ind: str, pose: Pose | None) -> None:
        if pose is None:
            return
        xyz, rpy = pose.written
        if self.formats is not None:
            self.leaf(ind, "origin", [("xyz", self.nums(pose.xyz) if xyz else None),
                                      ("rpy", self.nums(pose.rpy) if rpy else None)])
            return
        text = f' xyz="{self.nums(pose.xyz)}"' if xyz else ""
        if rpy:
            text += f' rpy="{self.nums(pose.rpy)}"'
        self.out.append(f"{ind}<origin{text}/>")

    def geometry(self, ind: str, geometry: Geometry, attrs: Attrs) -> None:
        self.out.append(f"{ind}<geometry{self.attrs(attrs)}>" if attrs else f"{ind}<geometry>")
        d = ind + IND
        match geometry:
            case Mesh():
                scale = self.nums(geometry.scale) if geometry.scale is not None else None
                if self.formats is None and not geometry.extra_attrs:
                    scale = f' scale="{scale}"' if scale is not None else ""
                    self.out.append(f'{d}<mesh filename="{self.escape(self.mesh_name(geometry))}"{scale}/>')
                else:
                    self.leaf(d, "mesh", [("filename", self.mesh_name(geometry)), ("scale", scale),
                                          *geometry.extra_attrs])
            case Box():
                self.leaf(d, "box", [("size", self.nums(geometry.size)), *geometry.extra_attrs])
            case Cylinder():
                self.numbers(d, "cylinder", ("radius", "length"), (geometry.radius, geometry.length),
                             geometry.extra_attrs)
            case Sphere():
                self.numbers(d, "sphere", ("radius",), (geometry.radius,), geometry.extra_attrs)
        self.out.append(f"{ind}</geometry>")

    def material(self, ind: str, material: Material) -> None:
        self.comments(ind, material.comments)
        head = f"{ind}<material{self.attrs([('name', material.name)])}"
        if material.rgba is None and material.texture is None:
            self.out.append(head + "/>")
            return
        self.out.append(head + ">")
        if material.rgba is not None:
            self.leaf(ind + IND, "color", [("rgba", self.nums(material.rgba))])
        if material.texture is not None:
            self.leaf(ind + IND, "texture", [("filename", material.texture or None)])
        self.out.append(f"{ind}</material>")

    def inertial(self, ind: str, inertial: Inertial) -> None:
        self.out.append(f"{ind}<inertial>")
        d = ind + IND
        self.pose(d, inertial.origin)
        self.numbers(d, "mass", ("value",), (inertial.mass,))
        i = inertial.inertia
        self.numbers(d, "inertia", _INERTIA, (i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz))
        for frag in inertial.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</inertial>")

    def shape(self, ind: str, tag: str, item: Visual | Collision) -> None:
        self.out.append(f"{ind}<{tag}{self.attrs([('name', item.name), *item.extra_attrs])}>")
        d = ind + IND
        self.pose(d, item.origin)
        self.geometry(d, item.geometry, item.geometry_attrs)
        if isinstance(item, Visual) and item.material is not None:
            if item.inline_material is not None:
                self.material(d, item.inline_material)
            else:  # names are never formatted
                self.out.append(f'{d}<material name="{self.escape(item.material)}"/>')
        for frag in item.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</{tag}>")

    def link(self, ind: str, link: Link) -> None:
        self.comments(ind, link.comments)
        head = f"{ind}<link{self.attrs([('name', link.name), *link.extra_attrs])}"
        body = link.inertial or link.visuals or link.collisions or link.extras
        if not body and not link.inner_comments:
            self.out.append(head + "/>")
            return
        self.out.append(head + ">")
        d = ind + IND
        self.comments(d, link.inner_comments)
        if link.inertial is not None:
            self.inertial(d, link.inertial)
        for visual in link.visuals:
            self.shape(d, "visual", visual)
        for collision in link.collisions:
            self.shape(d, "collision", collision)
        for frag in link.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</link>")

    def joint(self, ind: str, joint: Joint) -> None:
        self.comments(ind, joint.comments)
        attrs = self.attrs([("name", joint.name), ("type", joint.type), *joint.extra_attrs])
        self.out.append(f"{ind}<joint{attrs}>")
        d = ind + IND
        self.comments(d, joint.inner_comments)
        self.pose(d, joint.origin)
        self.out.append(f'{d}<parent link="{self.escape(joint.parent)}"/>')  # never formatted
        self.out.append(f'{d}<child link="{self.escape(joint.child)}"/>')
        if joint.axis is not None:
            if self.formats is None:
                self.out.append(f'{d}<axis xyz="{self.nums(joint.axis)}"/>')
            else:
                self.leaf(d, "axis", [("xyz", self.nums(joint.axis))])
        if (c := joint.calibration) is not None:
            self.numbers(d, "calibration", ("rising", "falling", "reference_position"),
                         (c.rising, c.falling, c.reference_position))
        if (dyn := joint.dynamics) is not None:
            self.numbers(d, "dynamics", ("damping", "friction"), (dyn.damping, dyn.friction),
                         dyn.extra_attrs)
        if (lim := joint.limit) is not None:
            self.numbers(d, "limit", ("lower", "upper", "effort", "velocity"),
                         (lim.lower, lim.upper, lim.effort, lim.velocity), lim.extra_attrs)
        if (m := joint.mimic) is not None:
            self.leaf(d, "mimic", [("joint", m.joint), ("multiplier", self.num(m.multiplier)),
                                   ("offset", self.num(m.offset))])
        if (s := joint.safety_controller) is not None:
            self.numbers(d, "safety_controller",
                         ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"),
                         (s.soft_lower_limit, s.soft_upper_limit, s.k_position, s.k_velocity))
        for frag in joint.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</joint>")


def to_string(robot: Robot, mesh_name: MeshNamer, formats: Formats | None = None) -> str:
    """The canonical URDF text of `robot`; `mesh_name` gives each mesh's filename; `formats`
    the number formats of `float_fmt_dict`, when given."""
    w = _Writer(mesh_name, formats)
    w.out.append('<?xml version="1.0" encoding="utf-8"?>')
    w.comments("", robot.header_comments)
    w.out.append(f"<robot{w.attrs([('name', robot.name), *robot.extra_attrs])}>")
    for name in sorted(robot.materials):
        w.material(IND, robot.materials[name])
    links = robot.links
    for joint, link in depth_first(robot):
        if joint is not None:
            w.joint(IND, joint)
        w.link(IND, links[link])
    for frag in robot.fragments:
        w.fragment(IND, frag)
    w.comments(IND, robot.trailing_comments)
    w.out.append("</robot>")
    return "\n".join(w.out) + "\n"
