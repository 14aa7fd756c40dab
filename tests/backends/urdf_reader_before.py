"""A frozen copy of backends/urdf_reader.py as it was before it became faster (issue 19), on
the frozen XmlSource beside it: tests/backends/test_reader_differential.py requires the new
reader to read every URDF into the same IR with the same diagnostics. A test fixture, never
imported by mpc. Changed since only where the reader's behaviour was meant to change:
issue 29 (a number that is not finite is E0480; a namespaced attribute is `prefix:name`).

The original docstring: URDF file → ir.Robot, reporting every problem with its line and column.

Elements URDF defines become typed IR values; everything else (top-level
`<gazebo>`, `<transmission>`, `<ros2_control>`, vendor tags, unknown children of
links and joints) is kept as opaque fragments that record the link and joint names
they mention. Comments are kept. Mesh files are resolved to paths, never opened.
"""

from __future__ import annotations

import math
from pathlib import Path

from lxml import etree

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.packages import PackageResolver
from mpc.core.span import Span
from mpc.ir.fragments import Fragment, FragmentRef, RefKind
from mpc.ir.geometry import Attrs, Box, Cylinder, Geometry, Mesh, MeshSource, Sphere, mesh_source
from mpc.ir.robot import (
    JOINT_TYPES,
    ZERO,
    Calibration,
    Collision,
    Dynamics,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mimic,
    Pose,
    Robot,
    SafetyController,
    Visual,
)
from mpc.ir.tree import check_tree
from tests.backends.refusal_before import refusal as refusal_before
from tests.backends.xml_source_before import XmlError, XmlSource, load, parse_floats

_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
# Elements inside links and joints that become IR values (anything else is a fragment).
_MODELLED = frozenset({
    "inertial", "visual", "collision", "origin", "geometry", "material", "mass", "inertia",
    "box", "cylinder", "sphere", "mesh", "color", "texture", "parent", "child", "axis", "limit",
    "dynamics", "mimic", "calibration", "safety_controller",
})


def read(path: Path, sink: Sink, resolver: PackageResolver | None = None,
         display: str | None = None) -> Robot | None:
    """Read the URDF at `path`; None when it has errors (all of them reported)."""
    src = load(path, sink, "URDF", display)
    if src is None:
        return None
    return _robot(src, sink, resolver, path.parent.resolve())


def read_text(data: bytes, file: str, base_dir: Path, sink: Sink,
              resolver: PackageResolver | None = None) -> Robot | None:
    """Read URDF text that no file holds (a xacro expansion), named `file` in diagnostics;
    relative mesh paths start at `base_dir`."""
    try:
        src = XmlSource.parse(data, file)
    except XmlError as e:
        sink.error(Span(file, e.line, e.col), "E0401", f"malformed XML in '{file}': {e.message}")
        return None
    return _robot(src, sink, resolver, base_dir)


def _robot(src: XmlSource, sink: Sink, resolver: PackageResolver | None, base_dir: Path) -> Robot | None:
    errors_before = sink.error_count
    robot = _Reader(src, sink, resolver or PackageResolver(), base_dir).robot()
    if robot is None or sink.error_count > errors_before:
        return None
    return robot


def _path(root: etree._Element, node: etree._Element) -> tuple[int, ...]:
    """The child indices (comments counted) from `root` down to its descendant `node`."""
    path: list[int] = []
    while node is not root:
        parent = node.getparent()
        path.append(parent.index(node))
        node = parent
    return tuple(reversed(path))


class _Reader:
    def __init__(self, src: XmlSource, sink: Sink, resolver: PackageResolver,
                 base_dir: Path) -> None:
        self.src, self.sink, self.resolver, self.base_dir = src, sink, resolver, base_dir
        self.link_names: set[str] = set()
        self.joint_names: set[str] = set()
        self.names: set[str] = set()  # both
        self.mesh_sources: dict[str, tuple[MeshSource, str | None]] = {}  # uri → (source, refusal)
        self.robot_nsmap = dict(src.root.nsmap)
        # What tostring adds to a fragment's start tag for the namespaces <robot> declares.
        self.namespace_declarations = [f' xmlns{":" + prefix if prefix else ""}="{uri}"'
                                       for prefix, uri in src.root.nsmap.items()]

    # -- helpers ---------------------------------------------------------------------------

    def error(self, el: etree._Element, code: str, message: str, attr: str | None = None,
              **kw: object) -> None:
        self.sink.error(self.src.span(el, attr), code, message, **kw)  # type: ignore[arg-type]

    def warn_unknown_attrs(self, el: etree._Element, known: tuple[str, ...], where: str) -> None:
        for name in el.keys():  # noqa: SIM118 (an element is no dict: `in el` is its children)
            if name not in known:
                self.sink.warning(
                    self.src.span(el, name), "W0401",
                    f"attribute '{name}' of <{el.tag}> in {where} is not URDF and is dropped",
                )

    def extra_attrs(self, el: etree._Element, known: tuple[str, ...]) -> Attrs:
        out, declare = [], {}
        for key, value in el.items():
            if key in known:
                continue
            if key.startswith("{"):  # issue 29: written `prefix:name`, declared where <robot> does not
                uri, local = key[1:].split("}", 1)
                prefixes = sorted(p for p, u in el.nsmap.items() if u == uri and p)
                prefix = "xml" if uri == "http://www.w3.org/XML/1998/namespace" else prefixes[0]
                key = f"{prefix}:{local}"
                if prefix != "xml" and self.robot_nsmap.get(prefix) != uri:
                    declare[f"xmlns:{prefix}"] = uri
            out.append((key, value))
        return (*out, *sorted(declare.items()))

    def floats(self, el: etree._Element, attr: str, n: int, where: str,
               required: bool = False) -> tuple[float, ...] | None:
        text = el.get(attr)
        if text is None:
            if required:
                self.error(el, "E0403", f"<{el.tag}> in {where} has no '{attr}' attribute")
            return None
        values = parse_floats(text)
        if values is not None and len(values) == n and not all(map(math.isfinite, values)):  # issue 29
            what = "a finite number" if n == 1 else f"{n} finite numbers"
            self.error(el, "E0480", f"'{attr}' of <{el.tag}> in {where} must be {what}, got '{text}'", attr,
                       hint="URDF readers (urdfdom, check_urdf) refuse nan and inf; write a finite number")
            return None
        if values is None or len(values) != n:
            what = "a number" if n == 1 else f"{n} numbers"
            self.error(el, "E0404", f"'{attr}' of <{el.tag}> in {where} must be {what}, "
                       f"got '{text}'", attr)
            return None
        return values

    def number(self, el: etree._Element, attr: str, where: str,
               required: bool = False) -> float | None:
        values = self.floats(el, attr, 1, where, required)
        return values[0] if values else None

    def pose(self, el: etree._Element | None, where: str) -> Pose | None:
        if el is None:
            return None
        self.warn_unknown_attrs(el, ("xyz", "rpy"), where)
        xyz = self.floats(el, "xyz", 3, where)
        rpy = self.floats(el, "rpy", 3, where)
        keys = el.keys()
        return Pose(xyz or ZERO, rpy or ZERO, ("xyz" in keys, "rpy" in keys))  # type: ignore[arg-type]

    def name(self, el: etree._Element, kind: str) -> str | None:
        name = el.get("name")
        if not name:
            self.error(el, "E0403", f"<{kind}> without a 'name' attribute")
            return None
        return name

    def children(self, el: etree._Element) -> list[etree._Element]:
        return [c for c in el if isinstance(c.tag, str)]

    @staticmethod
    def by_tag(el: etree._Element) -> tuple[list[etree._Element], dict[str, etree._Element]]:
        """The element children of `el` in order, and the first of each tag: what `el.find(tag)`
        gives for a plain tag, in one pass (each `find` call costs microseconds)."""
        kids: list[etree._Element] = []
        first: dict[str, etree._Element] = {}
        for child in el:
            tag = child.tag
            if isinstance(tag, str):
                kids.append(child)
                if tag not in first:
                    first[tag] = child
        return kids, first

    def fragment(self, el: etree._Element, comments: tuple[str, ...] = ()) -> Fragment:
        span = self.src.span(el)
        xml = etree.tostring(el, encoding="unicode", with_tail=False)
        # tostring re-declares every namespace in scope; <robot> declares them already.
        head_end = xml.find(">")
        head = xml[:head_end]
        for declaration in self.namespace_declarations:
            head = head.replace(declaration, "", 1)
        xml = head + xml[head_end:]
        if "\n" in xml:
            indent = " " * (span.col - 1)
            lines = xml.split("\n")
            xml = "\n".join([lines[0]] + [ln.removeprefix(indent) for ln in lines[1:]])
        return Fragment(tag=str(el.tag), xml=xml, refs=self.refs(el), comments=comments, span=span)

    def refs(self, el: etree._Element) -> tuple[FragmentRef, ...]:
        """Every attribute or text in the fragment that equals a link or joint name, in
        document order (each element's attributes, then its text)."""
        out: list[FragmentRef] = []
        names = self.names
        for node in el.iter(etree.Element):
            tag = node.tag
            for attr, value in node.items():
                name = value.strip()
                if name in names:
                    out.append(FragmentRef(_path(el, node), attr, self.kind_of(name, tag + attr), name))
            text = node.text
            if text and (name := text.strip()) and name in names:
                out.append(FragmentRef(_path(el, node), None, self.kind_of(name, tag), name))
        return tuple(out)

    def kind_of(self, name: str, hint: str) -> RefKind:
        """Whether the known `name` is a link's or a joint's; `hint` (where it stands) decides
        for a name that is both."""
        is_link, is_joint = name in self.link_names, name in self.joint_names
        if is_link and is_joint:
            return "joint" if "joint" in hint.lower() else "link"
        return "link" if is_link else "joint"

    def inner_comments(self, el: etree._Element) -> tuple[str, ...]:
        """Comments inside `el`, except those inside opaque fragments (which keep theirs)."""
        if next(el.iter(etree.Comment), None) is None:  # most elements hold none: one C-level walk
            return ()
        out: list[str] = []
        for child in el:
            if child.tag is etree.Comment:
                out.append(str(child.text))
            elif child.tag in _MODELLED:
                out.extend(self.inner_comments(child))
        return tuple(out)

    # -- elements --------------------------------------------------------------------------

    def robot(self) -> Robot | None:
        root, file = self.src.root, self.src.file
        if root.tag != "robot":
            self.error(root, "E0402", f"'{file}' is not a URDF: its root element is "
                       f"<{root.tag}>, not <robot>")
            return None
        name = root.get("name") or ""
        if not name:
            self.error(root, "E0403", f"<robot> in '{file}' has no 'name' attribute")
        elements = self.children(root)
        self.link_names = {e.get("name", "") for e in elements if e.tag == "link"}
        self.joint_names = {e.get("name", "") for e in elements if e.tag == "joint"}
        self.names = self.link_names | self.joint_names

        links: dict[str, Link] = {}
        joints: dict[str, Joint] = {}
        materials: dict[str, Material] = {}
        fragments: list[Fragment] = []
        pending: list[str] = []
        for el in root:
            if el.tag is etree.Comment:
                pending.append(str(el.text))
                continue
            if not isinstance(el.tag, str):
                continue
            comments, pending = tuple(pending), []
            if el.tag == "link":
                self.add(links, self.link(el, comments), el, "link")
            elif el.tag == "joint":
                self.add(joints, self.joint(el, comments), el, "joint")
            elif el.tag == "material":
                self.add(materials, self.material(el, comments, "<robot>"), el, "material")
            else:
                fragments.append(self.fragment(el, comments))

        header = []
        prev = root.getprevious()
        while prev is not None:
            if prev.tag is etree.Comment:
                header.append(str(prev.text))
            prev = prev.getprevious()
        extra = self.extra_attrs(root, ("name",)) + tuple(
            (f"xmlns:{p}" if p else "xmlns", uri) for p, uri in sorted(
                root.nsmap.items(), key=lambda kv: kv[0] or ""))
        if not links:
            self.error(root, "E0415", f"robot '{name or '?'}' in '{file}' has no links")
            return None
        robot_span = self.src.span(root)
        root_link = check_tree(links, joints, self.sink, robot_span, name)
        if root_link is None or not name:
            return None
        return Robot(
            name=name, root=root_link, links=links, joints=joints, materials=materials,
            fragments=tuple(fragments), extra_attrs=extra, header_comments=tuple(reversed(header)),
            trailing_comments=tuple(pending), span=robot_span,
        )

    def add(self, table: dict, item: object, el: etree._Element, kind: str) -> None:
        if item is None:
            return
        name = item.name  # type: ignore[attr-defined]
        if name in table:
            first = table[name].span
            self.error(el, "E0410", f"duplicate {kind} '{name}'", "name",
                       notes=((first, f"{kind} '{name}' is first defined here"),))
            return
        table[name] = item

    def link(self, el: etree._Element, comments: tuple[str, ...]) -> Link | None:
        name = self.name(el, "link")
        if name is None:
            return None
        where = f"link '{name}'"
        inertial, visuals, collisions, extras = None, [], [], []
        for child in self.children(el):
            if child.tag == "inertial":
                if inertial is not None:
                    self.error(child, "E0406", f"{where} has more than one <inertial>")
                inertial = self.inertial(child, where)
            elif child.tag == "visual":
                visuals.append(self.visual(child, where))
            elif child.tag == "collision":
                collisions.append(self.collision(child, where))
            else:
                extras.append(self.fragment(child))
        return Link(
            name=name, inertial=inertial,
            visuals=tuple(v for v in visuals if v is not None),
            collisions=tuple(c for c in collisions if c is not None),
            extra_attrs=self.extra_attrs(el, ("name",)), extras=tuple(extras),
            comments=comments, inner_comments=self.inner_comments(el), span=self.src.span(el),
        )

    def inertial(self, el: etree._Element, where: str) -> Inertial | None:
        kids, first = self.by_tag(el)
        mass_el, inertia_el = first.get("mass"), first.get("inertia")
        mass = self.number(mass_el, "value", where, True) if mass_el is not None else None
        if mass_el is None:
            self.error(el, "E0403", f"<inertial> in {where} has no <mass>")
        values = []
        if inertia_el is None:
            self.error(el, "E0403", f"<inertial> in {where} has no <inertia>")
        else:
            values = [self.number(inertia_el, k, where, True) for k in _INERTIA_KEYS]
        extras = tuple(self.fragment(c) for c in kids if c.tag not in ("origin", "mass", "inertia"))
        if mass is None or len(values) != 6 or None in values:
            return None
        return Inertial(mass=mass, inertia=Inertia(**dict(zip(_INERTIA_KEYS, values, strict=True))),
                        origin=self.pose(first.get("origin"), where), extras=extras)

    def geometry(self, el: etree._Element | None, parent: etree._Element,
                 where: str) -> Geometry | None:
        if el is None:
            self.error(parent, "E0403", f"<{parent.tag}> in {where} has no <geometry>")
            return None
        shapes = self.children(el)
        if len(shapes) != 1:
            self.error(el, "E0405", f"<geometry> in {where} must hold exactly one shape, "
                       f"found {len(shapes)}")
            return None
        shape = shapes[0]
        if shape.tag == "box":
            size = self.floats(shape, "size", 3, where, True)
            return Box(size=size, extra_attrs=self.extra_attrs(shape, ("size",))) if size else None  # type: ignore[arg-type]
        if shape.tag == "cylinder":
            r, h = self.number(shape, "radius", where, True), self.number(shape, "length", where, True)
            if r is None or h is None:
                return None
            return Cylinder(radius=r, length=h,
                            extra_attrs=self.extra_attrs(shape, ("radius", "length")))
        if shape.tag == "sphere":
            r = self.number(shape, "radius", where, True)
            if r is None:
                return None
            return Sphere(radius=r, extra_attrs=self.extra_attrs(shape, ("radius",)))
        if shape.tag == "mesh":
            uri = shape.get("filename")
            if not uri:
                self.error(shape, "E0403", f"<mesh> in {where} has no 'filename' attribute")
                return None
            scale = self.floats(shape, "scale", 3, where)
            if uri not in self.mesh_sources:  # a file's visuals and collisions share meshes
                source = mesh_source(self.resolver, uri, self.base_dir)
                refusal = refusal_before(self.resolver, source.path, self.base_dir) if source.path else None
                self.mesh_sources[uri] = source, refusal
            source, why = self.mesh_sources[uri]
            if why:
                self.error(shape, "E0650", f"mesh '{uri}' in {where} is not read: {why}", "filename")
                return None
            return Mesh(source=source,
                        scale=scale, span=self.src.span(shape, "filename"),  # type: ignore[arg-type]
                        extra_attrs=self.extra_attrs(shape, ("filename", "scale")))
        self.error(shape, "E0405", f"unsupported geometry <{shape.tag}> in {where}; URDF has "
                   "box, cylinder, sphere and mesh")
        return None

    def visual(self, el: etree._Element, where: str) -> Visual | None:
        kids, first = self.by_tag(el)
        geometry_el = first.get("geometry")
        geometry = self.geometry(geometry_el, el, where)
        material, inline = None, None
        material_el = first.get("material")
        if material_el is not None:
            material = material_el.get("name")
            if material is None:
                self.error(material_el, "E0403", f"<material> in {where} has no 'name' attribute")
            if len(material_el):
                inline = self.material(material_el, (), where)
        extras = tuple(self.fragment(c) for c in kids if c.tag not in ("origin", "geometry", "material"))
        if geometry is None:
            return None
        return Visual(
            geometry=geometry, name=el.get("name"), origin=self.pose(first.get("origin"), where),
            material=material, inline_material=inline,
            geometry_attrs=self.extra_attrs(geometry_el, ()) if geometry_el is not None else (),
            extra_attrs=self.extra_attrs(el, ("name",)), extras=extras, span=self.src.span(el),
        )

    def collision(self, el: etree._Element, where: str) -> Collision | None:
        kids, first = self.by_tag(el)
        geometry_el = first.get("geometry")
        geometry = self.geometry(geometry_el, el, where)
        extras = tuple(self.fragment(c) for c in kids if c.tag not in ("origin", "geometry"))
        if geometry is None:
            return None
        return Collision(
            geometry=geometry, name=el.get("name"), origin=self.pose(first.get("origin"), where),
            geometry_attrs=self.extra_attrs(geometry_el, ()) if geometry_el is not None else (),
            extra_attrs=self.extra_attrs(el, ("name",)), extras=extras, span=self.src.span(el),
        )

    def material(self, el: etree._Element, comments: tuple[str, ...], where: str) -> Material | None:
        name = el.get("name")
        if name is None:
            self.error(el, "E0403", f"<material> in {where} has no 'name' attribute")
            return None
        _, first = self.by_tag(el)
        color, texture = first.get("color"), first.get("texture")
        rgba = self.floats(color, "rgba", 4, f"material '{name}'", True) if color is not None else None
        return Material(name=name, rgba=rgba,  # type: ignore[arg-type]
                        texture=texture.get("filename", "") if texture is not None else None,
                        comments=comments, span=self.src.span(el))

    def joint(self, el: etree._Element, comments: tuple[str, ...]) -> Joint | None:
        name = self.name(el, "joint")
        if name is None:
            return None
        where = f"joint '{name}'"
        jtype = el.get("type")
        ok = True  # False: reported, but parent and child may still be known
        if jtype not in JOINT_TYPES:
            hint = did_you_mean(jtype or "", set(JOINT_TYPES))
            self.error(el, "E0422", f"{where} has unknown type '{jtype}'{hint}", "type",
                       hint="URDF joint types: " + ", ".join(JOINT_TYPES))
            ok = False
        kids, first = self.by_tag(el)
        ends = {}
        for end in ("parent", "child"):
            end_el = first.get(end)
            if end_el is None or not end_el.get("link"):
                self.error(end_el if end_el is not None else el, "E0403",
                           f"{where} has no <{end} link=…>")
                ok = False
            else:
                ends[end] = end_el.get("link")
        axis_el = first.get("axis")
        axis = self.floats(axis_el, "xyz", 3, where) if axis_el is not None else None
        limit = self.limit(first.get("limit"), where)
        if jtype in ("revolute", "prismatic") and (limit is None or limit.effort is None
                                                   or limit.velocity is None):
            self.error(el, "E0421", f"{where} is {jtype} but has no <limit> with effort and "
                       "velocity", "name")
            ok = False
        known = ("origin", "parent", "child", "axis", "limit", "dynamics", "mimic",
                 "calibration", "safety_controller")
        extras = tuple(self.fragment(c) for c in kids if c.tag not in known)
        if len(ends) < 2:
            return None
        if not ok:  # already reported; kept (as fixed) so that the tree checks do not cascade
            jtype = "fixed"
        return Joint(
            name=name, type=jtype, parent=ends["parent"], child=ends["child"],  # type: ignore[arg-type]
            origin=self.pose(first.get("origin"), where), axis=axis, limit=limit,  # type: ignore[arg-type]
            dynamics=self.dynamics(first.get("dynamics"), where),
            mimic=self.mimic(first.get("mimic"), where),
            calibration=self.calibration(first.get("calibration"), where),
            safety_controller=self.safety(first.get("safety_controller"), where),
            extra_attrs=self.extra_attrs(el, ("name", "type")), extras=extras,
            comments=comments, inner_comments=self.inner_comments(el), span=self.src.span(el),
        )

    def limit(self, el: etree._Element | None, where: str) -> Limit | None:
        if el is None:
            return None
        keys = ("lower", "upper", "effort", "velocity")
        return Limit(**{k: self.number(el, k, where) for k in keys},
                     extra_attrs=self.extra_attrs(el, keys))

    def dynamics(self, el: etree._Element | None, where: str) -> Dynamics | None:
        if el is None:
            return None
        keys = ("damping", "friction")
        return Dynamics(**{k: self.number(el, k, where) for k in keys},
                        extra_attrs=self.extra_attrs(el, keys))

    def mimic(self, el: etree._Element | None, where: str) -> Mimic | None:
        if el is None:
            return None
        self.warn_unknown_attrs(el, ("joint", "multiplier", "offset"), where)
        target = el.get("joint")
        if not target:
            self.error(el, "E0403", f"<mimic> in {where} has no 'joint' attribute")
            return None
        if target not in self.joint_names:
            # urdfdom accepts this and simulators ignore the mimic; keep it, but say so.
            self.sink.warning(self.src.span(el, "joint"), "W0411",
                              f"<mimic> in {where} refers to unknown joint '{target}'"
                              f"{did_you_mean(target, self.joint_names)}; it has no effect")
        return Mimic(joint=target, multiplier=self.number(el, "multiplier", where),
                     offset=self.number(el, "offset", where))

    def calibration(self, el: etree._Element | None, where: str) -> Calibration | None:
        if el is None:
            return None
        keys = ("rising", "falling", "reference_position")
        self.warn_unknown_attrs(el, keys, where)
        return Calibration(**{k: self.number(el, k, where) for k in keys})

    def safety(self, el: etree._Element | None, where: str) -> SafetyController | None:
        if el is None:
            return None
        keys = ("k_velocity", "k_position", "soft_lower_limit", "soft_upper_limit")
        self.warn_unknown_attrs(el, keys, where)
        k_velocity = self.number(el, "k_velocity", where, True)
        if k_velocity is None:
            return None
        return SafetyController(k_velocity=k_velocity,
                                **{k: self.number(el, k, where) for k in keys[1:]})
