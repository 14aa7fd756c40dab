"""SDFormat file (1.5–1.9, one `<model>`) → ir.Robot, every problem reported with its location.

Poses may be relative to `__model__`, links, joints and `<frame>`s; joint origins are
X_PC = X_MP⁻¹ · X_MC at q = 0, and the root link's frame is the robot's frame. A link
that is the child of several joints keeps one in the tree (revolute, prismatic or fixed
first, then document order); the others become cut joints. Where a tree joint's origin
is away from its child's origin, the child's IR frame moves there (a URDF joint sits at
its child's origin) and its content stays in place. Elements mpc does not model are kept
as `<gazebo>` fragments (model, link, joint) or extras. Does not open meshes; nested
models, `<include>` and ball/universal/… joints in the tree are E0202.
"""

from __future__ import annotations

import heapq
import math
from copy import deepcopy
from dataclasses import field, replace
from pathlib import Path

import numpy as np
from lxml import etree

from mpc.backends.xml import NOT_FINITE, XmlSource, finite_floats, load, parse_floats
from mpc.core.diagnostics import Sink
from mpc.core.files import resolved
from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.ir import transforms as tf
from mpc.ir.extras import CutJoint
from mpc.ir.fragments import Fragment, FragmentRef
from mpc.ir.geometry import Box, Cylinder, Geometry, Mesh, Sphere, mesh_source
from mpc.ir.kinematics import matrix_pose, pose_matrix
from mpc.ir.robot import (
    Collision,
    Dynamics,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Pose,
    Robot,
    Visual,
)

VERSIONS = ("1.5", "1.6", "1.7", "1.8", "1.9")
TREE_TYPES = ("revolute", "continuous", "prismatic", "fixed")  # the SDF joint types URDF has
CUT_TYPES = ("ball", "universal", "revolute2", "screw", "gearbox")  # read as loop closures only
UNBOUNDED = 1e16  # SDF's default position limit: none
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_COLOURS = {"ambient": "ambient", "diffuse": "rgba", "specular": "specular", "emissive": "emissive"}
_SHAPES = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",), "mesh": ("uri",)}


def read(path: Path, sink: Sink, resolver: PackageResolver | None = None) -> Robot | None:
    """Read the SDF at `path`; None when it has errors (all of them reported)."""
    src = load(path, sink, "SDF")
    if src is None:
        return None
    errors_before = sink.error_count
    robot = _Reader(src, sink, resolver or PackageResolver(), resolved(path.parent)).robot()
    return None if robot is None or sink.error_count > errors_before else robot


def _pose_dict(X: np.ndarray) -> dict[str, list[float]]:
    pose = matrix_pose(X)
    return {"xyz": list(pose.xyz), "rpy": list(pose.rpy)}


@record(frozen=False)
class _Joint:
    """An SDF joint as read, before the tree is chosen. axis: (xyz, the frame it is
    expressed in, None for the joint frame)."""

    el: etree._Element
    name: str
    type: str
    parent: str
    child: str
    order: int
    axis: tuple[tuple[float, ...], str | None] | None = None
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    annotations: dict[str, object] = field(default_factory=dict)


class _Reader:
    def __init__(self, src: XmlSource, sink: Sink, resolver: PackageResolver, base_dir: Path) -> None:
        self.src, self.sink, self.resolver, self.base_dir = src, sink, resolver, base_dir
        self.named: dict[str, etree._Element] = {}  # links, joints and frames share one namespace
        self.kinds: dict[str, str] = {}  # link and joint names, for fragment references
        self.X: dict[str, np.ndarray | None] = {"__model__": np.eye(4)}  # frames in the model
        self.visiting: set[str] = set()
        self.fragments: list[Fragment] = []
        self.world = False  # whether a joint attaches the model to the world

    def error(self, el: etree._Element, code: str, message: str, attr: str | None = None) -> None:
        self.sink.error(self.src.span(el, attr), code, message)

    def floats(self, el: etree._Element | None, n: int, where: str) -> tuple[float, ...] | None:
        if el is None:
            return None
        text = el.text or ""
        values = finite_floats(text)
        if values is NOT_FINITE and len(parse_floats(text) or ()) == n:
            self.error(el, "E0480", f"<{el.tag}> in {where} must be {n} finite number{'s' * (n > 1)}, "
                       f"got '{text.strip()}'")
            return None
        if values is None or values is NOT_FINITE or len(values) != n:
            self.error(el, "E0404", f"<{el.tag}> in {where} must be {n} number{'s' * (n > 1)}, "
                       f"got '{text.strip()}'")
            return None
        return tuple(values)

    def number(self, parent: etree._Element, tag: str, where: str, default: float | None = None
               ) -> float | None:
        values = self.floats(parent.find(tag), 1, where)
        return values[0] if values else default

    # -- frames ----------------------------------------------------------------------------

    def pose(self, el: etree._Element, where: str) -> tuple[Pose | None, str | None]:
        """(the `<pose>` of el, the frame it is relative to; None for el's default frame)."""
        p = el.find("pose")
        if p is None:
            return None, None
        if p.get("rotation_format", "euler_rpy") != "euler_rpy":
            self.error(p, "E0202", f"<pose rotation_format='{p.get('rotation_format')}'> in {where} "
                       "is not supported yet", "rotation_format")
            return None, None
        values = self.floats(p, 6, where)
        if values is None:
            return None, None
        degrees = p.get("degrees", "").strip().lower() in ("1", "true")
        rpy = tuple(math.radians(v) for v in values[3:]) if degrees else values[3:]
        # 1.5/1.6 wrote `frame` (usually empty) where 1.7 writes `relative_to`.
        return Pose(values[:3], rpy), p.get("relative_to") or p.get("frame") or None  # type: ignore[arg-type]

    def in_model(self, name: str, user: etree._Element) -> np.ndarray | None:
        """X_MF: the frame `name` (link, joint, frame) in the model frame, at q = 0."""
        if name in self.X:
            return self.X[name]
        el = self.named.get(name)
        if el is None:
            self.error(user, "E0411", f"<{user.tag}> '{user.get('name', '')}' refers to unknown frame "
                       f"'{name}'")
            return None
        if name in self.visiting:
            self.error(el, "E0413", f"the pose of <{el.tag}> '{name}' depends on itself")
            self.X[name] = None
            return None
        self.visiting.add(name)
        pose, rel = self.pose(el, f"<{el.tag}> '{name}'")
        if rel is None:  # SDF's default frames: a joint's child link, a frame's attached_to
            rel = el.findtext("child", "").strip() if el.tag == "joint" else el.get("attached_to", "")
        base = self.in_model(rel or "__model__", el)
        self.visiting.discard(name)
        self.X[name] = None if base is None else base @ pose_matrix(pose)
        return self.X[name]

    def local(self, el: etree._Element, link: str, shift: np.ndarray | None, where: str) -> Pose | None:
        """The pose of el (inertial, visual, collision) in its link's IR frame."""
        pose, rel = self.pose(el, where)
        if rel is not None and rel != link:
            X_ML, X_MF = self.in_model(link, el), self.in_model(rel, el)
            if X_ML is None or X_MF is None:
                return None
            pose = matrix_pose(tf.inverse(X_ML) @ X_MF @ pose_matrix(pose))
        return pose if shift is None else matrix_pose(tf.inverse(shift) @ pose_matrix(pose))

    # -- fragments -------------------------------------------------------------------------

    def fragment(self, els: list[etree._Element], reference: str | None = None, wrap: bool = True
                 ) -> Fragment:
        """els verbatim: together in a `<gazebo reference=…>` (the URDF way to carry SDF), or one."""
        root = etree.Element("gazebo") if wrap else deepcopy(els[0])
        if wrap:
            if reference is not None:
                root.set("reference", reference)
            root.extend(deepcopy(e) for e in els)
            etree.indent(root, space="  ")
        root.tail = None
        refs: list[FragmentRef] = []

        def walk(node: etree._Element, path: tuple[int, ...]) -> None:
            for attr, value in [*node.attrib.items(), (None, node.text or "")]:
                if kind := self.kinds.get(value.strip()):
                    refs.append(FragmentRef(path, attr, kind, value.strip()))  # type: ignore[arg-type]
            for i, child in enumerate(node):
                if isinstance(child.tag, str):
                    walk(child, (*path, i))

        walk(root, ())
        return Fragment(tag=str(root.tag), xml=etree.tostring(root, encoding="unicode"),
                        refs=tuple(refs), span=self.src.lazy_span(els[0]))

    def keep(self, el: etree._Element, known: tuple[str, ...], reference: str | None) -> None:
        unknown = [c for c in el if isinstance(c.tag, str) and c.tag not in known]
        if unknown:
            self.fragments.append(self.fragment(unknown, reference))

    def extras(self, el: etree._Element, known: tuple[str, ...]) -> tuple[Fragment, ...]:
        unknown = [c for c in el if isinstance(c.tag, str) and c.tag not in known]
        return tuple(self.fragment([c], wrap=False) for c in unknown)

    # -- the model -------------------------------------------------------------------------

    def robot(self) -> Robot | None:
        root, file = self.src.root, self.src.file
        if root.tag != "sdf":
            self.error(root, "E0402", f"'{file}' is not an SDF: its root element is <{root.tag}>, not <sdf>")
            return None
        if root.get("version") not in VERSIONS:
            self.error(root, "E0202", f"SDFormat version '{root.get('version')}' is not supported yet "
                       f"(mpc reads {', '.join(VERSIONS)})", "version")
            return None
        tops = [c for c in root if isinstance(c.tag, str)]
        if not tops:
            self.error(root, "E0403", f"'{file}' has no <model>")
            return None
        if tops[0].tag != "model" or len(tops) > 1:
            bad = tops[0] if tops[0].tag != "model" else tops[1]
            self.error(bad, "E0202", f"<{bad.tag}> next to or instead of one <model> is not supported yet")
            return None
        model, pending, comments = tops[0], [], {}
        name = model.get("name") or ""
        if not name:
            self.error(model, "E0403", f"<model> in '{file}' has no 'name' attribute")
        for el in model:
            if el.tag is etree.Comment:
                pending.append(str(el.text))
            elif el.tag in ("link", "joint", "frame"):
                self.declare(el, comments, tuple(pending))
                pending = []
            elif el.tag in ("model", "include"):
                self.error(el, "E0202", f"<{el.tag}> in model '{name}' is not supported yet")
        els = dict(self.named)
        self.kinds = {n: str(e.tag) for n, e in els.items() if e.tag != "frame"}
        # The model's own <pose> places it in a world, which the robot does not have.
        self.keep(model, ("link", "joint", "frame", "pose", "model", "include"), None)
        links = {n for n, e in els.items() if e.tag == "link"}
        if not links:
            self.error(model, "E0415", f"model '{name or '?'}' in '{file}' has no links")
            return None
        joints = [j for i, e in enumerate(els.values()) if e.tag == "joint" and (j := self.joint(e, i))]
        self.world = "world" not in links and any(j.parent == "world" for j in joints)
        if self.world:  # URDF's way to fix a robot to the world: a link named world
            self.X["world"] = np.eye(4)
        root_link, tree, cuts = self.tree(model, name, links, joints)
        if root_link is None or not name:
            return None
        return self.build(model, name, root_link, tree, cuts, comments, tuple(pending))

    def declare(self, el: etree._Element, comments: dict, before: tuple[str, ...]) -> None:
        name = el.get("name")
        if not name:
            self.error(el, "E0403", f"<{el.tag}> without a 'name' attribute")
        elif name in self.named:
            first = self.named[name]
            self.sink.error(self.src.span(el, "name"), "E0410", f"duplicate name '{name}': SDF links, "
                            "joints and frames share one namespace",
                            notes=((self.src.span(first), f"<{first.tag}> '{name}' is defined here"),))
        else:
            self.named[name], comments[name] = el, before

    def joint(self, el: etree._Element, order: int) -> _Joint | None:
        name, jtype = el.get("name", ""), el.get("type", "")
        where = f"joint '{name}'"
        if jtype not in TREE_TYPES + CUT_TYPES:
            self.error(el, "E0422", f"{where} has unknown type '{jtype}'", "type")
            return None
        ends = [el.findtext(end, "").strip() for end in ("parent", "child")]
        for end, link in zip(("parent", "child"), ends, strict=True):
            if self.kinds.get(link) != "link" and not (end == "parent" and link == "world"):
                end_el = el.find(end)
                self.error(end_el if end_el is not None else el, "E0411",
                           f"{where} refers to unknown {end} link '{link}'")
                return None
        j = _Joint(el, name, jtype, ends[0], ends[1], order)
        for tag in ("axis", "axis2"):
            if (axis_el := el.find(tag)) is None:
                continue
            xyz_el = axis_el.find("xyz")
            xyz = self.floats(xyz_el, 3, where) or (0.0, 0.0, 1.0)  # SDF's default axis
            frame = xyz_el.get("expressed_in") if xyz_el is not None else None
            if axis_el.findtext("use_parent_model_frame", "").strip() in ("1", "true"):  # 1.5, 1.6
                frame = "__model__"
            if tag == "axis2":
                j.annotations["axis2"] = list(xyz)
                continue
            j.axis = (xyz, frame or None)
            j.dynamics, j.limit = self.dynamics(axis_el, j), self.limit(axis_el, j)
        if j.axis is None and jtype == "revolute":
            j.type = "continuous"
        self.keep(el, ("pose", "parent", "child", "axis", "axis2"), name)
        return j

    def dynamics(self, axis: etree._Element, j: _Joint) -> Dynamics | None:
        if (el := axis.find("dynamics")) is None:
            return None
        where = f"joint '{j.name}'"
        for key in ("spring_reference", "spring_stiffness"):  # the language keeps springs as annotations
            if (value := self.number(el, key, where)) is not None:
                j.annotations[key] = value
        damping, friction = (self.number(el, k, where) for k in ("damping", "friction"))
        return None if damping is None and friction is None else Dynamics(damping=damping, friction=friction)

    def limit(self, axis: etree._Element, j: _Joint) -> Limit | None:
        el = axis.find("limit")
        lower, upper, effort, velocity = (self.number(el, k, f"joint '{j.name}'") if el is not None else None
                                          for k in ("lower", "upper", "effort", "velocity"))
        effort, velocity = (None if v is None or v < 0 else v for v in (effort, velocity))  # -1: none
        if j.type == "revolute" and (lower is None or lower <= -UNBOUNDED) and (
                upper is None or upper >= UNBOUNDED):
            j.type = "continuous"
        if j.type == "continuous":
            lower = upper = None
        elif j.type != "fixed":
            lower, upper = -UNBOUNDED if lower is None else lower, UNBOUNDED if upper is None else upper
        if (lower, upper, effort, velocity) == (None, None, None, None):
            return None
        return Limit(lower=lower, upper=upper, effort=effort, velocity=velocity)

    def tree(self, model: etree._Element, name: str, links: set[str], joints: list[_Joint]
             ) -> tuple[str | None, list[_Joint], list[_Joint]]:
        """The root link, the tree joints from the root down, the cut joints."""
        children = {j.child for j in joints}
        roots = ["world"] * self.world + sorted((lk for lk in links if lk not in children),
                                                key=lambda lk: self.named[lk].sourceline or 0)
        if len(roots) != 1:
            if roots:
                self.error(model, "E0414", f"model '{name}' has {len(roots)} root links "
                           f"({', '.join(roots)}); mpc reads one tree (free links are not supported yet)")
            else:
                self.error(model, "E0413", f"model '{name}' has no root link: its joints form a cycle")
            return None, [], []
        out: dict[str, list[_Joint]] = {}
        for j in joints:
            out.setdefault(j.parent, []).append(j)
        heap = [(j.type not in TREE_TYPES, j.order, j.name, j) for j in out.get(roots[0], [])]
        heapq.heapify(heap)
        reached, tree = {roots[0]}, []
        while heap:
            j = heapq.heappop(heap)[3]
            if j.child not in reached:
                reached.add(j.child)
                tree.append(j)
                for k in out.get(j.child, []):
                    heapq.heappush(heap, (k.type not in TREE_TYPES, k.order, k.name, k))
        if lost := sorted(links - reached):
            self.error(model, "E0413", f"model '{name}': links {', '.join(lost)} form a cycle that is not "
                       f"connected to the root link '{roots[0]}'")
            return None, [], []
        for j in tree:
            if j.type not in TREE_TYPES:
                self.error(j.el, "E0202", f"joint '{j.name}' of type '{j.type}' is needed in the kinematic "
                           f"tree (to reach link '{j.child}'), which is not supported yet", "type")
        in_tree = {j.name for j in tree}
        return roots[0], tree, [j for j in joints if j.name not in in_tree]

    # -- the robot -------------------------------------------------------------------------

    def build(self, model: etree._Element, name: str, root: str, tree: list[_Joint], cuts: list[_Joint],
              comments: dict, trailing: tuple[str, ...]) -> Robot | None:
        link_els = {n: e for n, e in self.named.items() if e.tag == "link"}
        X_M = {n: self.in_model(n, e) for n, e in link_els.items()}
        if self.world:
            X_M["world"] = np.eye(4)
        X_CJ: dict[str, np.ndarray] = {}  # each joint's frame in its child's SDF frame
        shift: dict[str, np.ndarray] = {}  # a link's IR frame in its SDF frame, where they differ
        in_tree = {j.name for j in tree}
        for j in tree + cuts:
            X_CJ[j.name] = np.eye(4)
            if self.pose(j.el, f"joint '{j.name}'") != (None, None):  # else exactly the child's frame
                X_MJ, X_MC = self.in_model(j.name, j.el), X_M[j.child]
                if X_MJ is None or X_MC is None:
                    return None
                X_CJ[j.name] = tf.inverse(X_MC) @ X_MJ
            if j.name in in_tree and np.linalg.norm(X_CJ[j.name][:3, 3]) > 1e-12:
                shift[j.child] = np.eye(4)
                shift[j.child][:3, 3] = X_CJ[j.name][:3, 3]
        if any(X is None for X in X_M.values()):
            return None
        X_IR = {n: X @ shift[n] if n in shift else X for n, X in X_M.items()}

        def origin(j: _Joint) -> Pose:
            return matrix_pose(tf.inverse(X_IR[j.parent]) @ X_IR[j.child])

        links = {"world": Link(name="world")} if self.world else {}
        links |= {n: self.link(e, shift.get(n), comments[n]) for n, e in link_els.items()}
        joints = {j.name: Joint(
            name=j.name, type=j.type, parent=j.parent, child=j.child, origin=origin(j),  # type: ignore[arg-type]
            axis=None if j.type == "fixed" else self.axis(j, X_CJ[j.name], X_M[j.child]),  # type: ignore[arg-type]
            limit=j.limit, dynamics=j.dynamics, annotations=j.annotations, comments=comments[j.name],
            inner_comments=_comments(j.el), span=self.src.lazy_span(j.el))
            for j in sorted(tree, key=lambda j: j.order)}
        cut_joints = {}
        for j in cuts:  # the joint frame and axis, as seen from the child link's IR frame
            X_C_J = tf.inverse(shift[j.child]) @ X_CJ[j.name] if j.child in shift else X_CJ[j.name]
            notes: dict[str, object] = {"joint_origin": _pose_dict(X_C_J), **j.annotations}
            if j.axis is not None:
                notes["axis"] = list(self.axis(j, X_CJ[j.name], X_M[j.child]))  # type: ignore[arg-type]
            cut_joints[j.name] = CutJoint(name=j.name, type=j.type, parent=j.parent, child=j.child,
                                          origin=origin(j), annotations=notes, span=self.src.lazy_span(j.el))
        # The root's pose in the model (e.g. a standing height) is not a pose between links.
        annotations = {} if np.array_equal(X_IR[root], np.eye(4)) else {
            "sdf": {"root_pose_in_model": _pose_dict(X_IR[root])}}  # type: ignore[arg-type]
        header, prev = [], self.src.root.getprevious()
        while prev is not None:
            if prev.tag is etree.Comment:
                header.append(str(prev.text))
            prev = prev.getprevious()
        return Robot(name=name, root=root, links=links, joints=joints, fragments=tuple(self.fragments),
                     header_comments=tuple(reversed(header)), trailing_comments=trailing,
                     cut_joints=cut_joints, annotations=annotations, span=self.src.lazy_span(model))

    def axis(self, j: _Joint, X_CJ: np.ndarray, X_MC: np.ndarray) -> tuple[float, ...]:
        """The joint axis in the child link's frame (in SDF: in the joint frame, or expressed_in)."""
        xyz, frame = j.axis or ((0.0, 0.0, 1.0), None)
        if frame is None and np.array_equal(X_CJ[:3, :3], np.eye(3)):
            return xyz
        X_MF = self.in_model(frame, j.el) if frame is not None else None
        R = X_CJ[:3, :3] if frame is None else X_MC[:3, :3].T @ (np.eye(4) if X_MF is None else X_MF)[:3, :3]
        return tuple(float(v) for v in R @ np.array(xyz))

    def link(self, el: etree._Element, shift: np.ndarray | None, comments: tuple[str, ...]) -> Link:
        name = el.get("name", "")
        where = f"link '{name}'"
        inertials = el.findall("inertial")
        if len(inertials) > 1:
            self.error(inertials[1], "E0406", f"{where} has more than one <inertial>")
        # SDF's defaults: a link without <inertial> weighs 1 kg, with a unit inertia.
        i_el = inertials[0] if inertials else etree.Element("inertial")
        inertia_el = i_el.find("inertia")
        values = {k: self.number(inertia_el, k, where, float(k[1] == k[2])) if inertia_el is not None
                  else float(k[1] == k[2]) for k in _INERTIA}
        inertial = Inertial(mass=self.number(i_el, "mass", where, 1.0), inertia=Inertia(**values),  # type: ignore[arg-type]
                            origin=self.local(i_el, name, shift, where),
                            extras=self.extras(i_el, ("pose", "mass", "inertia")))
        visuals, collisions = [], []
        for item in el:
            if item.tag not in ("visual", "collision") or (
                    geometry := self.geometry(item.find("geometry"), item, where)) is None:
                continue
            kw = {"geometry": geometry, "name": item.get("name"), "span": self.src.lazy_span(item),
                  "origin": self.local(item, name, shift, where)}
            if item.tag == "collision":
                collisions.append(Collision(**kw, extras=self.extras(item, ("pose", "geometry"))))
                continue
            material = self.material(item, f"{name}__{item.get('name', len(visuals))}", where)
            visuals.append(Visual(**kw, material=material and material.name, inline_material=material,
                                  extras=self.extras(item, ("pose", "geometry", "material", "transparency"))))
        self.keep(el, ("pose", "inertial", "visual", "collision"), name)
        return Link(name=name, inertial=inertial, visuals=tuple(visuals), collisions=tuple(collisions),
                    comments=comments, inner_comments=_comments(el), span=self.src.lazy_span(el))

    def material(self, visual: etree._Element, name: str, where: str) -> Material | None:
        el, transparency = visual.find("material"), self.number(visual, "transparency", where)
        if el is None and transparency is None:
            return None
        colours: dict[str, tuple[float, ...]] = {}
        for tag, key in _COLOURS.items():
            if (colour_el := el.find(tag) if el is not None else None) is None:
                continue
            values = finite_floats(colour_el.text or "")
            if values is None or values is NOT_FINITE or len(values) not in (3, 4):
                self.error(colour_el, "E0404", f"<{tag}> in {where} must be 3 or 4 numbers")
            else:
                colours[key] = tuple(values) + (1.0,) * (4 - len(values))
        if "rgba" not in colours and "ambient" in colours:  # URDF has one colour: take what SDF shows
            colours["rgba"] = colours["ambient"]
        # Scripts, shaders and PBR maps: kept as written, for formats that can hold them.
        others = {str(c.tag): etree.tostring(c, encoding="unicode", with_tail=False)
                  for c in (el if el is not None else ()) if isinstance(c.tag, str) and c.tag not in _COLOURS}
        return Material(name=name, transparency=transparency, annotations=others, **colours)  # type: ignore[arg-type]

    def geometry(self, el: etree._Element | None, parent: etree._Element, where: str) -> Geometry | None:
        if el is None:
            self.error(parent, "E0403", f"<{parent.tag}> in {where} has no <geometry>")
            return None
        shapes = [c for c in el if isinstance(c.tag, str)]
        if len(shapes) != 1:
            self.error(el, "E0405", f"<geometry> in {where} must hold exactly one shape, found {len(shapes)}")
            return None
        s = shapes[0]
        if s.tag not in _SHAPES or s.find("submesh") is not None:
            what = "<submesh>" if s.tag == "mesh" else f"geometry <{s.tag}>"
            self.error(s, "E0202", f"{what} in {where} is not supported yet; mpc reads box, cylinder, "
                       "sphere and mesh")
            return None
        if missing := [t for t in _SHAPES[s.tag] if s.find(t) is None]:
            self.error(s, "E0403", f"<{s.tag}> in {where} has no <{missing[0]}>")
            return None
        if s.tag == "mesh":
            uri_el = s.find("uri")
            uri = (uri_el.text or "").strip()
            # model://NAME/… is found as package://NAME/… is (Gazebo searches its model path).
            found = mesh_source(self.resolver, "package://" + uri[8:] if uri.startswith("model://") else uri,
                                self.base_dir)
            if found.path is not None and (why := self.resolver.refusal(found.path, self.base_dir)):
                self.error(uri_el, "E0650", f"mesh '{uri}' in {where} is not read: {why}")
                return None
            return Mesh(source=replace(found, uri=uri), scale=self.floats(s.find("scale"), 3, where),  # type: ignore[arg-type]
                        span=self.src.lazy_span(uri_el))
        v = {t: self.floats(s.find(t), 3 if t == "size" else 1, where) for t in _SHAPES[s.tag]}
        if None in v.values():
            return None
        if s.tag == "box":
            return Box(size=v["size"])  # type: ignore[arg-type]
        if s.tag == "cylinder":
            return Cylinder(radius=v["radius"][0], length=v["length"][0])  # type: ignore[index]
        return Sphere(radius=v["radius"][0])  # type: ignore[index]


def _comments(el: etree._Element) -> tuple[str, ...]:
    return tuple(str(c.text) for c in el if c.tag is etree.Comment)
