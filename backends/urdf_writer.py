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


class _Writer:
    """The lines of one URDF text.

    Each element is written as one f-string: a number's text needs no escaping and goes in
    as it is (in the float format of its attribute, when float formats apply), a name is
    escaped once for the whole text. The attributes a source wrote beyond URDF's go through
    `attrs`, formatted as they always were (by their own names).
    """

    def __init__(self, mesh_name: MeshNamer, formats: Formats | None = None) -> None:
        self.mesh_name, self.formats = mesh_name, formats
        self.out: list[str] = []
        # The text of each number, tuple and attribute value written so far: a robot repeats
        # many of them.
        self.texts: dict[float, str] = {}
        self.tuple_texts: dict[tuple[float, ...], str] = {}
        self.escaped: dict[str, str] = {}
        self.origins: dict[int, str] = {}  # `origin`: the text of each Pose, by its id

    def text(self, x: float) -> str:
        text = self.texts.get(x)
        if text is None:
            text = self.texts[x] = fmt_float(x)
        return text

    def nums(self, xs: tuple[float, ...], key: str) -> str:
        """The text of the numbers `xs` of attribute `key`."""
        if type(xs) is not tuple:  # a list: not hashable
            text = fmt_floats(xs)
        else:
            text = self.tuple_texts.get(xs)
            if text is None:
                text = self.tuple_texts[xs] = " ".join(map(self.text, xs))
        return text if self.formats is None else self.formats(key, text)  # type: ignore[return-value]

    def number(self, key: str, x: float | None) -> str:
        """` key="x"` (x in the float format of `key`, when float formats apply), or nothing
        for None."""
        if x is None:
            return ""
        text = self.texts.get(x)
        if text is None:
            text = self.texts[x] = fmt_float(x)
        return f' {key}="{text}"' if self.formats is None else f' {key}="{self.formats(key, text)}"'

    def escape(self, value: str) -> str:
        safe = self.escaped.get(value)
        if safe is None:
            safe = self.escaped[value] = xml_escape.attribute(value)
        return safe

    def attrs(self, pairs: list[tuple[str, str | None]] | Attrs, formatted: bool = False) -> str:
        """` key="value"` for each pair whose value is not None, escaped; `formatted`: the values
        in the float formats of their keys (a leaf's attributes, as URDF_KEYS name them)."""
        if formatted and self.formats is not None:
            pairs = [(k, self.formats(k, v)) for k, v in pairs]
        text = ""
        for key, value in pairs:
            if value is not None:
                text += f' {key}="{self.escape(value)}"'
        return text

    def named(self, name: str | None, extra: Attrs) -> str:
        """`attrs([("name", name), *extra])`, without the list for the commonest case: a link,
        visual or collision with its name alone."""
        if extra:
            return self.attrs([("name", name), *extra])
        return f' name="{self.escape(name)}"' if name is not None else ""

    def comments(self, ind: str, comments: tuple[str, ...]) -> None:
        for c in comments:
            self.out.append(f"{ind}<!--{c}-->")

    def fragment(self, ind: str, frag: Fragment) -> None:
        if frag.comments:
            self.comments(ind, frag.comments)
        xml = frag.xml
        if "\n\n" not in xml and xml[-1:] != "\n":  # every line indented: no empty one
            self.out.append(ind + xml.replace("\n", "\n" + ind))
            return
        first, *rest = xml.split("\n")
        self.out.append(ind + first)
        self.out.extend((ind + ln) if ln else ln for ln in rest)

    def origin(self, ind: str, pose: Pose) -> str:
        # A reader shares a Pose among the elements that wrote it alike (most of a URDF's
        # <origin>s): its text is made once, by the identity of the Pose (alive while written).
        text = self.origins.get(id(pose))
        if text is None:
            xyz, rpy = pose.written
            xyz_text = f' xyz="{self.nums(pose.xyz, "xyz")}"' if xyz else ""
            rpy_text = f' rpy="{self.nums(pose.rpy, "rpy")}"' if rpy else ""
            text = self.origins[id(pose)] = f"<origin{xyz_text}{rpy_text}/>"
        return ind + text

    def geometry(self, ind: str, geometry: Geometry, attrs: Attrs) -> str:
        """The <geometry> element's lines, as one text."""
        d = ind + IND
        match geometry:
            case Mesh():
                scale = (f' scale="{self.nums(geometry.scale, "scale")}"'
                         if geometry.scale is not None else "")
                extra = self.attrs(geometry.extra_attrs, True) if geometry.extra_attrs else ""
                name = self.escape(self.mesh_name(geometry))
                shape = f'\n{d}<mesh filename="{name}"{scale}{extra}/>'
            case Box():
                shape = (f'\n{d}<box size="{self.nums(geometry.size, "size")}"'
                         f'{self.attrs(geometry.extra_attrs, True)}/>')
            case Cylinder():
                shape = (f'\n{d}<cylinder{self.number("radius", geometry.radius)}'
                         f'{self.number("length", geometry.length)}'
                         f'{self.attrs(geometry.extra_attrs, True)}/>')
            case Sphere():
                shape = (f'\n{d}<sphere{self.number("radius", geometry.radius)}'
                         f'{self.attrs(geometry.extra_attrs, True)}/>')
            case _:
                shape = ""
        return f"{ind}<geometry{self.attrs(attrs) if attrs else ''}>{shape}\n{ind}</geometry>"

    def material(self, ind: str, material: Material) -> None:
        if material.comments:
            self.comments(ind, material.comments)
        head = f"{ind}<material{self.attrs([('name', material.name)])}"
        if material.rgba is None and material.texture is None:
            self.out.append(head + "/>")
            return
        self.out.append(head + ">")
        if material.rgba is not None:
            self.out.append(f'{ind}{IND}<color rgba="{self.nums(material.rgba, "rgba")}"/>')
        if material.texture is not None:
            texture = self.attrs([("filename", material.texture or None)])
            self.out.append(f"{ind}{IND}<texture{texture}/>")
        self.out.append(f"{ind}</material>")

    def inertial(self, ind: str, inertial: Inertial) -> None:
        d = ind + IND
        i, number = inertial.inertia, self.number
        if inertial.origin is not None:
            self.out.append(f"{ind}<inertial>\n{self.origin(d, inertial.origin)}")
        else:
            self.out.append(f"{ind}<inertial>")
        self.out.append(
            f'{d}<mass{number("value", inertial.mass)}/>\n'
            f'{d}<inertia{number("ixx", i.ixx)}{number("ixy", i.ixy)}{number("ixz", i.ixz)}'
            f'{number("iyy", i.iyy)}{number("iyz", i.iyz)}{number("izz", i.izz)}/>')
        for frag in inertial.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</inertial>")

    def shape(self, ind: str, tag: str, item: Visual | Collision) -> None:
        d = ind + IND
        head = f"{ind}<{tag}{self.named(item.name, item.extra_attrs)}>"
        if item.origin is not None:
            head += "\n" + self.origin(d, item.origin)
        self.out.append(f"{head}\n{self.geometry(d, item.geometry, item.geometry_attrs)}")
        if isinstance(item, Visual) and item.material is not None:
            if item.inline_material is not None:
                self.material(d, item.inline_material)
            else:
                self.out.append(f'{d}<material name="{self.escape(item.material)}"/>')
        for frag in item.extras:
            self.fragment(d, frag)
        self.out.append(f"{ind}</{tag}>")

    def link(self, ind: str, link: Link) -> None:
        if link.comments:
            self.comments(ind, link.comments)
        head = f"{ind}<link{self.named(link.name, link.extra_attrs)}"
        body = link.inertial or link.visuals or link.collisions or link.extras
        if not body and not link.inner_comments:
            self.out.append(head + "/>")
            return
        self.out.append(head + ">")
        d = ind + IND
        if link.inner_comments:
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
        if joint.comments:
            self.comments(ind, joint.comments)
        if joint.extra_attrs:
            attrs = self.attrs([("name", joint.name), ("type", joint.type), *joint.extra_attrs])
        else:
            attrs = f' name="{self.escape(joint.name)}" type="{self.escape(joint.type)}"'
        self.out.append(f"{ind}<joint{attrs}>")
        d, number = ind + IND, self.number
        if joint.inner_comments:
            self.comments(d, joint.inner_comments)
        lines = [f"{self.origin(d, joint.origin)}\n" if joint.origin is not None else "",
                 f'{d}<parent link="{self.escape(joint.parent)}"/>\n',  # links are never formatted
                 f'{d}<child link="{self.escape(joint.child)}"/>']
        if joint.axis is not None:
            lines.append(f'\n{d}<axis xyz="{self.nums(joint.axis, "xyz")}"/>')
        if (c := joint.calibration) is not None:
            lines.append(f'\n{d}<calibration{number("rising", c.rising)}{number("falling", c.falling)}'
                         f'{number("reference_position", c.reference_position)}/>')
        if (dyn := joint.dynamics) is not None:
            lines.append(f'\n{d}<dynamics{number("damping", dyn.damping)}'
                         f'{number("friction", dyn.friction)}{self.attrs(dyn.extra_attrs, True)}/>')
        if (lim := joint.limit) is not None:
            lines.append(f'\n{d}<limit{number("lower", lim.lower)}{number("upper", lim.upper)}'
                         f'{number("effort", lim.effort)}{number("velocity", lim.velocity)}'
                         f'{self.attrs(lim.extra_attrs, True)}/>')
        if (m := joint.mimic) is not None:
            lines.append(f'\n{d}<mimic{self.attrs([("joint", m.joint)])}'
                         f'{number("multiplier", m.multiplier)}{number("offset", m.offset)}/>')
        if (s := joint.safety_controller) is not None:
            lines.append(f'\n{d}<safety_controller{number("soft_lower_limit", s.soft_lower_limit)}'
                         f'{number("soft_upper_limit", s.soft_upper_limit)}'
                         f'{number("k_position", s.k_position)}{number("k_velocity", s.k_velocity)}/>')
        self.out.append("".join(lines))
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
