"""URDF file → ir.Robot, reporting every problem with its line and column.

Elements URDF defines become typed IR values; everything else (top-level
`<gazebo>`, `<transmission>`, `<ros2_control>`, vendor tags, unknown children of
links and joints) is kept as opaque fragments that record the link and joint names
they mention. Comments are kept. Mesh files are resolved to paths, never opened.
"""

from __future__ import annotations

import functools
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

from lxml import etree

from mpc.backends.urdf_fragments import Fragments
from mpc.backends.xml import NOT_FINITE, XmlError, XmlSource, finite_floats, load, parse_floats
from mpc.core.cycles import paused_cycle_collection
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.packages import PackageResolver
from mpc.core.record import maker
from mpc.core.span import Span
from mpc.ir.fragments import Fragment, FragmentRef
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

NONE_MATERIAL = "None"  # Phobos's name for no material

_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_UNREAD = object()  # _Reader.numbers: a text not read yet
# Pose.written: one tuple of each kind for all poses (a read makes hundreds).
_WRITTEN = {(x, r): (x, r) for x in (False, True) for r in (False, True)}
_NAME, _NAME_TYPE, _POSE, _MESH = ("name",), ("name", "type"), ("xyz", "rpy"), ("filename", "scale")
_LIMIT, _DYNAMICS = ("lower", "upper", "effort", "velocity"), ("damping", "friction")
# The children of a joint that are no fragments.
_JOINT_CHILDREN = frozenset({"origin", "parent", "child", "axis", "limit", "dynamics", "mimic",
                             "calibration", "safety_controller"})
# The filenames of the meshes the reader reads, in document order (plain strings: an lxml
# "smart" string would hold its element and the whole tree). Any child of a link, not just a
# <visual> or <collision>: the union of those two paths costs libxml2 a sort into document
# order, 2.5 times the time of this path. A mesh of another child (a fragment's) is located too,
# but neither read nor reported.
_LINK_MESHES = etree.XPath("link/*/geometry/mesh/@filename", smart_strings=False)
# Elements inside links and joints that become IR values (anything else is a fragment).
_MODELLED = frozenset({
    "inertial", "visual", "collision", "origin", "geometry", "material", "mass", "inertia",
    "box", "cylinder", "sphere", "mesh", "color", "texture", "parent", "child", "axis", "limit",
    "dynamics", "mimic", "calibration", "safety_controller",
})


@functools.cache
def _makers() -> SimpleNamespace:
    """A maker of each IR record a read makes (core/record.py: maker, a quarter of the class
    call's time; a URDF read makes 1,600 of them), written at the first read rather than at
    import: `mpc check` imports this module on every save. Each class opts in to it with
    `@record(..., bulk=True)` (the list: tests/core/test_record.py BULK)."""
    return SimpleNamespace(
        pose=maker(Pose), ref=maker(FragmentRef), robot=maker(Robot),
        link=maker(Link), inertial=maker(Inertial), inertia=maker(Inertia), box=maker(Box),
        cylinder=maker(Cylinder), sphere=maker(Sphere), mesh=maker(Mesh), visual=maker(Visual),
        collision=maker(Collision), material=maker(Material), joint=maker(Joint), limit=maker(Limit),
        dynamics=maker(Dynamics), mimic=maker(Mimic), calibration=maker(Calibration),
        safety=maker(SafetyController))


def read(path: Path, sink: Sink, resolver: PackageResolver | None = None,
         display: str | None = None) -> Robot | None:
    """Read the URDF at `path`; None when it has errors (all of them reported)."""
    src = load(path, sink, "URDF", display)
    if src is None:
        return None
    resolver = resolver or PackageResolver()
    return _robot(src, sink, resolver, resolver.resolved(path.parent))


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
    with paused_cycle_collection():  # a read makes thousands of records and no garbage cycles
        robot = _Reader(src, sink, resolver or PackageResolver(), base_dir).robot()
    if robot is None or sink.error_count > errors_before:
        return None
    return robot


_XML_NAMESPACE = "http://www.w3.org/XML/1998/namespace"  # the `xml:` prefix's, never declared


def _one_number(text: str) -> tuple[float, ...] | None:
    """finite_floats(text), for the text of one number without calling it: most of a URDF's
    numbers stand alone in their attribute, and a read parses hundreds (two calls each)."""
    if "_" not in text and " " not in text:
        try:
            x = float(text)
        except ValueError:
            return finite_floats(text)
        return (x,) if x - x == 0.0 else NOT_FINITE  # inf - inf and nan - nan are nan
    return finite_floats(text)


class _Reader:
    def __init__(self, src: XmlSource, sink: Sink, resolver: PackageResolver,
                 base_dir: Path) -> None:
        self.src, self.sink, self.resolver, self.base_dir = src, sink, resolver, base_dir
        self.new = _makers()
        self.mesh_sources: dict[str, tuple[MeshSource, str | None]] = {}  # uri → (source, refusal)
        # The numbers of each attribute text read so far (parse_floats), and the values of
        # <origin>, <limit> and <dynamics> by their attributes: a URDF repeats many. A value
        # is kept only when reading it reported nothing.
        self.numbers: dict[str, tuple[float, ...] | None] = {}
        self.poses: dict[tuple[tuple[str, str], ...], Pose] = {}
        self.limits: dict[tuple[tuple[str, str], ...], Limit | Dynamics] = {}
        # The elements that hold a comment somewhere inside (most hold none).
        self.commented = {parent for comment in src.root.iter(etree.Comment)
                          for parent in comment.iterancestors()}
        self.fragments = Fragments(src, self.new.ref)
        self.fragment = self.fragments.fragment
        self.joint_names = self.fragments.joint_names  # filled by robot(), first
        self.locate_meshes()

    def locate_meshes(self) -> None:
        """Find the file of every mesh the links name, in one pass before the walk: done at
        each <mesh> among the walk's other work, the same calls took twice their time
        (bench/README.md, 2026-11-28)."""
        resolver, base_dir = self.resolver, self.base_dir
        sources = {uri: mesh_source(resolver, uri, base_dir)
                   for uri in dict.fromkeys(_LINK_MESHES(self.src.root)) if uri}
        # Whether each may be read, once every package they name is found (their roots).
        refusals = iter(resolver.refusals([s.path for s in sources.values() if s.path is not None], base_dir))
        self.mesh_sources = {uri: (source, next(refusals) if source.path is not None else None)
                             for uri, source in sources.items()}

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
        items = el.items()
        for item in items:
            if item[0] not in known:
                return self.prefixed(el, tuple([item for item in items if item[0] not in known]))
        return ()

    def prefixed(self, el: etree._Element, attrs: Attrs) -> Attrs:
        """The attributes with each namespaced name (lxml's `{uri}name`, which no XML file
        may hold) written `prefix:name` as the file wrote it, and the declaration of each
        prefix that `<robot>` does not declare: the URDF written keeps them well-formed."""
        for key, _ in attrs:  # most hold none: a loop, not any() over a generator
            if key[0] == "{":
                break
        else:
            return attrs
        out: list[tuple[str, str]] = []
        declare: dict[str, str] = {}
        for key, value in attrs:
            if key[0] == "{":
                uri, local = key[1:].split("}", 1)
                prefix = "xml" if uri == _XML_NAMESPACE else next(
                    p for p, u in sorted(el.nsmap.items(), key=lambda pu: pu[0] or "") if u == uri and p)
                key = f"{prefix}:{local}"
                if prefix != "xml" and self.fragments.nsmap.get(prefix) != uri:
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
        values = self.numbers.get(text, _UNREAD)
        if values is _UNREAD:
            values = self.numbers[text] = finite_floats(text)
        if values is NOT_FINITE or not isinstance(values, tuple) or len(values) != n:
            self.not_numbers(el, attr, n, where, text, values is NOT_FINITE)
            return None
        return values

    def number(self, el: etree._Element, attr: str, where: str,
               required: bool = False) -> float | None:
        """floats(…, 1, …)[0], without the tuple for the caller (most numbers are read here)."""
        text = el.get(attr)
        if text is None:
            if required:
                self.error(el, "E0403", f"<{el.tag}> in {where} has no '{attr}' attribute")
            return None
        values = self.numbers.get(text, _UNREAD)
        if values is _UNREAD:
            values = self.numbers[text] = _one_number(text)
        if values is NOT_FINITE or not isinstance(values, tuple) or len(values) != 1:
            self.not_numbers(el, attr, 1, where, text, values is NOT_FINITE)
            return None
        return values[0]

    def not_numbers(self, el: etree._Element, attr: str, n: int, where: str, text: str,
                    infinite: bool = False) -> None:
        what = "a number" if n == 1 else f"{n} numbers"
        if infinite and len(parse_floats(text) or ()) == n:
            what = "a finite number" if n == 1 else f"{n} finite numbers"
            self.error(el, "E0480", f"'{attr}' of <{el.tag}> in {where} must be {what}, got '{text}'", attr,
                       hint="URDF readers (urdfdom, check_urdf) refuse nan and inf; write a finite number")
            return
        self.error(el, "E0404", f"'{attr}' of <{el.tag}> in {where} must be {what}, got '{text}'", attr)

    def pose(self, el: etree._Element | None, where: str) -> Pose | None:
        if el is None:
            return None
        items = tuple(el.items())
        pose = self.poses.get(items)
        if pose is not None:
            return pose
        keys = [key for key, _ in items]
        has_xyz, has_rpy = "xyz" in keys, "rpy" in keys
        if len(keys) > has_xyz + has_rpy:
            self.warn_unknown_attrs(el, _POSE, where)
        xyz = self.floats(el, "xyz", 3, where) if has_xyz else None
        rpy = self.floats(el, "rpy", 3, where) if has_rpy else None
        pose = self.new.pose(xyz or ZERO, rpy or ZERO, _WRITTEN[has_xyz, has_rpy])
        if len(keys) == has_xyz + has_rpy and (xyz or not has_xyz) and (rpy or not has_rpy):
            self.poses[items] = pose
        return pose

    def name(self, el: etree._Element, kind: str) -> str | None:
        name = el.get("name")
        if not name:
            self.error(el, "E0403", f"<{kind}> without a 'name' attribute")
            return None
        return name

    def named(self, el: etree._Element, known: tuple[str, ...] = _NAME) -> tuple[str | None, Attrs]:
        """The 'name' attribute of `el` and its attributes not `known`, from one look at them
        (links, joints, visuals and collisions have a name and seldom anything else)."""
        items = el.items()
        if len(items) == 1 and items[0][0] == "name":
            return items[0][1], ()
        return el.get("name"), self.prefixed(el, tuple([item for item in items if item[0] not in known]))

    def sort_children(self, el: etree._Element, known: frozenset[str]
                      ) -> tuple[dict[str, etree._Element], tuple[Fragment, ...]]:
        """The first element child of each tag (what `el.find(tag)` gives for a plain tag), and
        the children whose tags are not `known` as fragments, in one pass (each `find` call
        costs microseconds; a fragment reports nothing, so it may be made first)."""
        first: dict[str, etree._Element] = {}
        extras: list[Fragment] = []
        for child in el:
            tag = child.tag
            if tag.__class__ is str:
                if tag not in first:
                    first[tag] = child
                if tag not in known:
                    extras.append(self.fragment(child))
        return first, tuple(extras)

    def inner_comments(self, el: etree._Element) -> tuple[str, ...]:
        """Comments inside `el`, except those inside opaque fragments (which keep theirs)."""
        if el not in self.commented:
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
        names, children = self.fragments, list(root)  # kept: lxml makes each proxy once then
        tags = [el.tag for el in children]  # each a new string (or function) lxml makes when asked
        for el, tag in zip(children, tags, strict=True):  # every name first: fragments, mimics name them
            if tag == "link":
                names.link_names.add(el.get("name", ""))
            elif tag == "joint":
                names.joint_names.add(el.get("name", ""))
        names.names, names.both = names.link_names | names.joint_names, names.link_names & names.joint_names

        links: dict[str, Link] = {}
        joints: dict[str, Joint] = {}
        materials: dict[str, Material] = {}
        fragments: list[Fragment] = []
        pending: list[str] = []
        for el, tag in zip(children, tags, strict=True):
            if tag.__class__ is not str:
                if tag is etree.Comment:
                    pending.append(str(el.text))
                continue
            comments, pending = tuple(pending), []
            if tag == "link":
                self.add(links, self.link(el, comments), el, "link")
            elif tag == "joint":
                self.add(joints, self.joint(el, comments), el, "joint")
            elif tag == "material":
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
                self.fragments.nsmap.items(), key=lambda kv: kv[0] or ""))
        if not links:
            self.error(root, "E0415", f"robot '{name or '?'}' in '{file}' has no links")
            return None
        robot_span = self.src.lazy_span(root)
        links = self.without_none_material(links, materials)
        root_link = check_tree(links, joints, self.sink, robot_span, name)
        if root_link is None or not name:
            return None
        return self.new.robot(
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
        name, extra_attrs = self.named(el)
        if not name:
            self.error(el, "E0403", "<link> without a 'name' attribute")
            return None
        where = f"link '{name}'"
        inertial, visuals, collisions, extras = None, [], [], []
        for child in el:
            tag = child.tag
            if tag == "visual":
                if (visual := self.visual(child, where)) is not None:
                    visuals.append(visual)
            elif tag == "collision":
                if (collision := self.collision(child, where)) is not None:
                    collisions.append(collision)
            elif tag == "inertial":
                if inertial is not None:
                    self.error(child, "E0406", f"{where} has more than one <inertial>")
                inertial = self.inertial(child, where)
            elif tag.__class__ is str:
                extras.append(self.fragment(child))
        return self.new.link(
            name=name, inertial=inertial, visuals=tuple(visuals), collisions=tuple(collisions),
            extra_attrs=extra_attrs, extras=tuple(extras),
            comments=comments, inner_comments=self.inner_comments(el), span=self.src.lazy_span(el),
        )

    def inertial(self, el: etree._Element, where: str) -> Inertial | None:
        origin_el = mass_el = inertia_el = None
        extras: list[Fragment] = []
        for child in el:  # sort_children without a dict, for one of the commonest elements
            tag = child.tag
            if tag == "mass":
                if mass_el is None:
                    mass_el = child
            elif tag == "inertia":
                if inertia_el is None:
                    inertia_el = child
            elif tag == "origin":
                if origin_el is None:
                    origin_el = child
            elif tag.__class__ is str:
                extras.append(self.fragment(child))
        mass = self.number(mass_el, "value", where, True) if mass_el is not None else None
        if mass_el is None:
            self.error(el, "E0403", f"<inertial> in {where} has no <mass>")
        values = []
        if inertia_el is None:
            self.error(el, "E0403", f"<inertial> in {where} has no <inertia>")
        else:
            number = self.number
            values = [number(inertia_el, k, where, True) for k in _INERTIA_KEYS]
        if mass is None or len(values) != 6 or None in values:
            return None
        ixx, ixy, ixz, iyy, iyz, izz = values
        inertia = self.new.inertia(ixx=ixx, ixy=ixy, ixz=ixz, iyy=iyy, iyz=iyz, izz=izz)
        return self.new.inertial(mass=mass, inertia=inertia, origin=self.pose(origin_el, where),
                                 extras=tuple(extras) if extras else ())

    def geometry(self, el: etree._Element | None, parent: etree._Element,
                 where: str) -> Geometry | None:
        if el is None:
            self.error(parent, "E0403", f"<{parent.tag}> in {where} has no <geometry>")
            return None
        shape, count = None, 0
        for child in el:
            if child.tag.__class__ is str:
                shape, count = shape if count else child, count + 1
        if count != 1:
            self.error(el, "E0405", f"<geometry> in {where} must hold exactly one shape, found {count}")
            return None
        if shape.tag == "mesh":  # type: ignore[union-attr]
            return self.mesh(shape, where)
        if shape.tag == "box":
            size = self.floats(shape, "size", 3, where, True)
            return self.new.box(size=size, extra_attrs=self.extra_attrs(shape, ("size",))) if size else None
        if shape.tag == "cylinder":
            r, h = self.number(shape, "radius", where, True), self.number(shape, "length", where, True)
            if r is None or h is None:
                return None
            return self.new.cylinder(radius=r, length=h,
                            extra_attrs=self.extra_attrs(shape, ("radius", "length")))
        if shape.tag == "sphere":
            r = self.number(shape, "radius", where, True)
            if r is None:
                return None
            return self.new.sphere(radius=r, extra_attrs=self.extra_attrs(shape, ("radius",)))
        self.error(shape, "E0405", f"unsupported geometry <{shape.tag}> in {where}; URDF has "
                   "box, cylinder, sphere and mesh")
        return None

    def mesh(self, el: etree._Element, where: str) -> Mesh | None:
        uri = el.get("filename")
        if not uri:
            self.error(el, "E0403", f"<mesh> in {where} has no 'filename' attribute")
            return None
        scale = self.floats(el, "scale", 3, where)
        source, why = self.mesh_sources[uri]  # locate_meshes found them all
        if why:
            self.error(el, "E0650", f"mesh '{uri}' in {where} is not read: {why}", "filename")
            return None
        return self.new.mesh(source=source, scale=scale, span=self.src.lazy_span(el, "filename"),
                    extra_attrs=self.extra_attrs(el, _MESH))

    def shape_children(self, el: etree._Element, visual: bool) -> tuple[
            etree._Element | None, etree._Element | None, etree._Element | None, tuple[Fragment, ...]]:
        """The first <origin>, <geometry> and (of a visual) <material> of a visual or collision,
        and the other children as fragments: sort_children without a dict for the commonest
        elements."""
        origin = geometry = material = None
        extras: list[Fragment] = []
        for child in el:
            tag = child.tag
            if tag == "geometry":
                if geometry is None:
                    geometry = child
            elif tag == "origin":
                if origin is None:
                    origin = child
            elif tag == "material" and visual:
                if material is None:
                    material = child
            elif tag.__class__ is str:
                extras.append(self.fragment(child))
        return origin, geometry, material, tuple(extras) if extras else ()

    def without_none_material(self, links: dict[str, Link],
                              materials: dict[str, Material]) -> dict[str, Link]:
        """`links` without Phobos's colourless material 'None' (which Phobos writes for visuals
        without a material, and check_urdf calls undefined); W0621 names it and its links."""
        none = materials.get(NONE_MATERIAL)
        if none is not None and (none.rgba is not None or none.texture):
            return links  # a material of that name, with a colour: the user's
        users = {name: link for name, link in links.items()
                 if any(v.material == NONE_MATERIAL and v.inline_material is None for v in link.visuals)}
        if not users and none is None:
            return links
        if none is not None:
            del materials[NONE_MATERIAL]
        first = none.span if none is not None else next(
            v.span for v in next(iter(users.values())).visuals if v.material == NONE_MATERIAL)
        shown = ", ".join(f"'{n}'" for n in list(users)[:8])
        shown += f" and {len(users) - 8} more" if len(users) > 8 else ""
        assert first is not None  # the reader gives every element its span
        self.sink.warning(first, "W0621", f"material '{NONE_MATERIAL}' has no colour (Phobos writes it for "
                          "visuals without a material); it is left out"
                          + (f", from the visuals of link{'s' * (len(users) > 1)} {shown}" if users else ""))
        return {**links, **{name: replace(link, visuals=tuple(
            replace(v, material=None) if v.material == NONE_MATERIAL and v.inline_material is None else v
            for v in link.visuals)) for name, link in users.items()}}

    def visual(self, el: etree._Element, where: str) -> Visual | None:
        origin_el, geometry_el, material_el, extras = self.shape_children(el, True)
        geometry = self.geometry(geometry_el, el, where)
        material, inline = None, None
        if material_el is not None:
            material = material_el.get("name")
            if material is None:
                self.error(material_el, "E0403", f"<material> in {where} has no 'name' attribute")
            if len(material_el):
                inline = self.material(material_el, (), where)
        if geometry is None:
            return None
        name, extra_attrs = self.named(el)
        return self.new.visual(
            geometry=geometry, name=name, origin=self.pose(origin_el, where),
            material=material, inline_material=inline,
            geometry_attrs=self.prefixed(geometry_el, tuple(geometry_el.items())),  # type: ignore[union-attr]
            extra_attrs=extra_attrs, extras=extras, span=self.src.lazy_span(el),
        )

    def collision(self, el: etree._Element, where: str) -> Collision | None:
        origin_el, geometry_el, _, extras = self.shape_children(el, False)
        geometry = self.geometry(geometry_el, el, where)
        if geometry is None:
            return None
        name, extra_attrs = self.named(el)
        return self.new.collision(
            geometry=geometry, name=name, origin=self.pose(origin_el, where),
            geometry_attrs=self.prefixed(geometry_el, tuple(geometry_el.items())),  # type: ignore[union-attr]
            extra_attrs=extra_attrs, extras=extras, span=self.src.lazy_span(el),
        )

    def material(self, el: etree._Element, comments: tuple[str, ...], where: str) -> Material | None:
        name = el.get("name")
        if name is None:
            self.error(el, "E0403", f"<material> in {where} has no 'name' attribute")
            return None
        color = texture = None
        for child in el:  # the first of each, as el.find would give (each call costs microseconds)
            if child.tag == "color" and color is None:
                color = child
            elif child.tag == "texture" and texture is None:
                texture = child
        rgba = self.floats(color, "rgba", 4, f"material '{name}'", True) if color is not None else None
        return self.new.material(name=name, rgba=rgba,
                        texture=texture.get("filename", "") if texture is not None else None,
                        comments=comments, span=self.src.lazy_span(el))

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
        first, extras = self.sort_children(el, _JOINT_CHILDREN)
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
        if len(ends) < 2:
            return None
        if not ok:  # already reported; kept (as fixed) so that the tree checks do not cascade
            jtype = "fixed"
        return self.new.joint(
            name=name, type=jtype, parent=ends["parent"], child=ends["child"],
            origin=self.pose(first.get("origin"), where), axis=axis, limit=limit,
            dynamics=self.dynamics(first.get("dynamics"), where),
            mimic=self.mimic(first.get("mimic"), where),
            calibration=self.calibration(first.get("calibration"), where),
            safety_controller=self.safety(first.get("safety_controller"), where),
            extra_attrs=self.extra_attrs(el, _NAME_TYPE), extras=extras,
            comments=comments, inner_comments=self.inner_comments(el), span=self.src.lazy_span(el),
        )

    def limit(self, el: etree._Element | None, where: str) -> Limit | None:
        if el is None:
            return None
        items = tuple(el.items())
        limit = self.limits.get(items)
        if limit is not None:
            return limit  # type: ignore[return-value]
        reported = len(self.sink.diagnostics)
        limit = self.new.limit(lower=self.number(el, "lower", where), upper=self.number(el, "upper", where),
                      effort=self.number(el, "effort", where),
                      velocity=self.number(el, "velocity", where), extra_attrs=self.extra_attrs(el, _LIMIT))
        if len(self.sink.diagnostics) == reported:
            self.limits[items] = limit
        return limit

    def dynamics(self, el: etree._Element | None, where: str) -> Dynamics | None:
        if el is None:
            return None
        items = ("dynamics", *el.items())
        dynamics = self.limits.get(items)
        if dynamics is not None:
            return dynamics  # type: ignore[return-value]
        reported = len(self.sink.diagnostics)
        dynamics = self.new.dynamics(damping=self.number(el, "damping", where),
                            friction=self.number(el, "friction", where),
                            extra_attrs=self.extra_attrs(el, _DYNAMICS))
        if len(self.sink.diagnostics) == reported:
            self.limits[items] = dynamics
        return dynamics

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
        return self.new.mimic(joint=target, multiplier=self.number(el, "multiplier", where),
                     offset=self.number(el, "offset", where))

    def calibration(self, el: etree._Element | None, where: str) -> Calibration | None:
        if el is None:
            return None
        keys = ("rising", "falling", "reference_position")
        self.warn_unknown_attrs(el, keys, where)
        return self.new.calibration(**{k: self.number(el, k, where) for k in keys})

    def safety(self, el: etree._Element | None, where: str) -> SafetyController | None:
        if el is None:
            return None
        keys = ("k_velocity", "k_position", "soft_lower_limit", "soft_upper_limit")
        self.warn_unknown_attrs(el, keys, where)
        k_velocity = self.number(el, "k_velocity", where, True)
        if k_velocity is None:
            return None
        return self.new.safety(k_velocity=k_velocity,
                                **{k: self.number(el, k, where) for k in keys[1:]})
