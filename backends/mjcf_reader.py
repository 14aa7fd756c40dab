"""MJCF file (MuJoCo's format) → ir.Robot, read through MuJoCo's own `MjSpec` and compiled
`MjModel`, so that MuJoCo's rules decide what the file means: default classes, `<include>`,
`meshdir`, the `<compiler>` settings (angle units, Euler sequences, `autolimits`,
`inertiafromgeom`), `<frame>`s, `fromto`, mesh scale and refpos/refquat all reach the IR as
MuJoCo compiles them. Every number comes from the compiled model; names, mesh files and the
elements the IR cannot hold come from the spec.

Files are read here, in Python, and handed to MuJoCo (its `include` and `assets`), so that
the read rule (core/files.py) refuses an `<include>` or a mesh outside the project before
MuJoCo sees it, and the build's fingerprints (core/reads.py) hold every included file and mesh.

What maps to what (specs/definition.md, "MJCF input models"):
- a body → a link whose frame is the body's (moved to its joint's anchor when the joint sits
  off the body's origin, as a URDF joint sits at its child's origin); a body with no joint
  → a fixed joint `<body>_fixed`; hinge → revolute (limited) or continuous, slide →
  prismatic; several joints in one body → a chain through massless links `<body>__<joint>`;
  the only body under `<worldbody>`, when it has no joint or a free joint, is the robot's
  root (fixed or floating, as a URDF's root is); a free joint on one of several top bodies
  → a `floating` joint from a root link `world` (MuJoCo's world body);
- geoms → visuals and collisions: a geom that collides (contype or conaffinity not 0) is a
  collision, and also a visual unless it is in group 3 (Menagerie's collision group); one
  that never collides is a visual; a capsule becomes a cylinder and two spheres;
- inertials, damping, friction loss and armature (a joint annotation) from the compiled
  model; sites → frames (massless links on fixed joints); actuators on joints → motors;
  equality connect → a ball loop closure, weld → a fixed one; keyframes → poses;
  materials and geom colours → materials.
What the IR cannot hold (ball joints: fixed at their reference; ellipsoids, planes, height
fields; tendons, sensors, plugins, …) is named in one warning, W0440. MuJoCo's own errors
are E0440 at the file, line and column MuJoCo names.
"""

from __future__ import annotations

import os
import re
from collections import Counter
from dataclasses import field, replace
from pathlib import Path
from typing import Any

import numpy as np

from mpc.backends.xml import XmlSource, load
from mpc.core.diagnostics import Sink
from mpc.core.files import resolved, why_absent
from mpc.core.names import free_name
from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir import transforms as tf
from mpc.ir.extras import CutJoint, Motor
from mpc.ir.geometry import Box, Cylinder, Geometry, Mesh, MeshSource, Sphere
from mpc.ir.kinematics import matrix_pose
from mpc.ir.robot import (
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
    Visual,
)

UNBOUNDED = 1e16  # an unlimited slide's range in the IR (a prismatic joint needs one)
COLLISION_GROUP = 3  # Menagerie's group of collision-only geoms
_FREE, _BALL, _SLIDE, _HINGE = 0, 1, 2, 3
_EQ_JOINT = 2  # mjEQ_JOINT
_MESH_GEOM, _PRIMITIVES = 7, {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box"}
_UNHELD_GEOMS = {0: "plane", 1: "height field", 4: "ellipsoid", 8: "sdf"}
# What a compiled model counts that the IR has no place for (its name in W0440 → MjModel's count).
_MODEL_COUNTS = {"tendon": "ntendon", "sensor": "nsensor", "plugin": "nplugin", "custom numeric": "nnumeric",
                 "custom text": "ntext", "custom tuple": "ntuple", "camera": "ncam", "light": "nlight",
                 "flex": "nflex", "skin": "nskin", "texture": "ntex", "contact exclusion": "nexclude",
                 "contact pair": "npair"}
_LINE = re.compile(r"line (\d+)")
_ELEMENT = re.compile(r"Element '([\w-]+)'")
_ATTRIBUTE = re.compile(r"attribute:? '([\w-]+)'")


def read(path: Path, sink: Sink, resolver: PackageResolver | None = None) -> Robot | None:
    """Read the MJCF at `path`; None when it has errors (all of them reported)."""
    mujoco = _mujoco()
    from mpc.backends.mujoco_module import warnings_into

    src = load(path, sink, "MJCF")
    if src is None:
        return None
    if src.root.tag == "robot" and path.suffix.lower() == ".xml":  # a URDF named .xml, as before
        from mpc.backends import urdf_reader

        return urdf_reader.read(path, sink, resolver)
    if src.root.tag != "mujoco":
        sink.error(src.span(src.root), "E0402", f"'{src.file}' is not an MJCF: its root element is "
                   f"<{src.root.tag}>, not <mujoco>")
        return None
    files = _Files(src, sink, resolver or PackageResolver(), resolved(path.parent))
    errors_before = sink.error_count
    files.gather_includes(src)
    if sink.error_count > errors_before:
        return None
    said: list[str] = []  # MuJoCo's warnings
    try:
        with warnings_into(said):
            spec = mujoco.MjSpec.from_file(str(path), include=files.includes)
    except ValueError as e:
        files.mujoco_error(str(e))
        return None
    files.gather_meshes(spec)
    files.gather_other_files(spec)
    if sink.error_count > errors_before:
        return None
    spec.assets = files.assets
    try:
        with warnings_into(said):
            model = spec.compile()
    except ValueError as e:
        files.mujoco_error(str(e))
        return None
    for message in dict.fromkeys(said):  # MuJoCo's warnings (a deprecated attribute): said once
        sink.warning(src.span(src.root), "W0441", f"MuJoCo warns about '{src.file}': {message}")
    if what := _not_finite(model):
        sink.error(src.span(src.root), "E0480", f"'{src.file}' compiles to a number that is not finite "
                   f"({what}); no output may hold one")
        return None
    robot = _Builder(spec, model, files).robot()
    return None if sink.error_count > errors_before else robot


def _mujoco() -> Any:
    """MuJoCo's module, imported when a file is read."""
    from mpc.backends.mujoco_module import mujoco

    return mujoco


# The compiled numbers the robot is made of, and what each is (E0480).
_NUMBERS = {"body_pos": "a body's position", "body_quat": "a body's orientation",
            "body_mass": "a body's mass", "body_ipos": "a centre of mass", "body_iquat": "an inertial frame",
            "body_inertia": "an inertia", "jnt_pos": "a joint's position", "jnt_axis": "a joint's axis",
            "jnt_range": "a joint's range", "qpos0": "a joint's reference", "dof_damping": "a damping",
            "dof_frictionloss": "a friction loss", "dof_armature": "an armature",
            "jnt_stiffness": "a stiffness", "qpos_spring": "a spring reference", "geom_size": "a geom's size",
            "geom_pos": "a geom's position", "geom_quat": "a geom's orientation", "geom_rgba": "a colour",
            "mesh_pos": "a mesh's centre", "mesh_quat": "a mesh's axes", "mesh_scale": "a mesh's scale",
            "site_pos": "a site's position", "site_quat": "a site's orientation", "key_qpos": "a keyframe",
            "eq_data": "an equality's anchor", "actuator_gainprm": "an actuator's gain",
            "actuator_biasprm": "an actuator's bias", "actuator_ctrlrange": "a control range",
            "actuator_forcerange": "a force range", "actuator_gear": "a gear", "mat_rgba": "a colour",
            "jnt_actfrcrange": "an actuator force range"}


def _not_finite(model: Any) -> str | None:
    """What the first number of the compiled model that is not finite is, or None."""
    return next((what for name, what in _NUMBERS.items()
                 if not np.all(np.isfinite(np.asarray(getattr(model, name))))), None)


@record(frozen=False)
class _Files:
    """The MJCF's files: the main one, those it includes, its meshes; read here, under the
    read rule, and handed to MuJoCo."""

    src: XmlSource
    sink: Sink
    resolver: PackageResolver
    base_dir: Path
    sources: list[XmlSource] = field(default_factory=list)
    includes: dict[str, bytes] = field(default_factory=dict)
    assets: dict[str, bytes] = field(default_factory=dict)
    mesh_paths: dict[str, tuple[str, Path]] = field(default_factory=dict)  # name → (uri, path)
    _spans: dict[str, dict[str, Span]] = field(default_factory=dict)

    def gather_includes(self, src: XmlSource) -> None:
        """Every file `src` includes (`<include>`, and the `<model>` assets that `<attach>`
        attaches), nested ones too; MuJoCo finds them from the main file's folder."""
        self.sources.append(src)
        for el in src.root.iter("include", "model"):
            name = el.get("file", "")
            if not name or name in self.includes:
                continue
            path = Path(name) if os.path.isabs(name) else self.base_dir / name
            if why := self.resolver.refusal(path, self.base_dir):
                self.sink.error(src.span(el, "file"), "E0650", f"<{el.tag}> '{name}' is not read: {why}")
                continue
            if not path.is_file():
                self.sink.error(src.span(el, "file"), "E0601", f"<{el.tag}> '{name}' {why_absent(path)}")
                continue
            included = load(path, self.sink, "MJCF")
            if included is None:
                continue
            self.includes[name] = path.read_bytes()
            self.gather_includes(included)

    def element(self, tag: str, **attrs: str) -> tuple[XmlSource, Any] | None:
        """The first element `tag` with those attributes, in the main file or an included one."""
        for src in self.sources:
            for el in src.root.iter(tag):
                if all(el.get(k) == v for k, v in attrs.items()):
                    return src, el
        return None

    def spans(self, tag: str) -> dict[str, Span]:
        """The span of each named element `tag` (the language server's hover and go-to), found
        when first asked for."""
        if tag not in self._spans:
            self._spans[tag] = {el.get("name", ""): src.lazy_span(el) for src in reversed(self.sources)
                                for el in src.root.iter(tag) if el.get("name")}
        return self._spans[tag]

    def span_of(self, tag: str, **attrs: str) -> Span:
        found = self.element(tag, **attrs)
        return found[0].span(found[1]) if found is not None else self.src.span(self.src.root)

    def gather_meshes(self, spec: Any) -> None:
        meshdir = spec.meshdir or ""
        for mesh in spec.meshes:
            if not mesh.file:
                continue  # vertices given in the file: left out (W0440)
            uri = mesh.file if os.path.isabs(mesh.file) else os.path.join(meshdir, mesh.file)
            path = self.base_dir / uri
            span = self.span_of("mesh", file=mesh.file)
            if why := self.resolver.refusal(path, self.base_dir):
                self.sink.error(span, "E0650",
                                f"mesh '{mesh.file}' of <mesh> '{mesh.name}' is not read: {why}")
                continue
            if not path.is_file():
                self.sink.error(span, "E0602",
                                f"mesh file '{path}' of <mesh> '{mesh.name}' {why_absent(path)}")
                continue
            data = path.read_bytes()
            self.assets[os.path.join(spec.modelfiledir, uri)] = data
            if path.suffix.lower() == ".msh":  # MuJoCo's own mesh format: its STL, in the cache
                try:
                    converted = msh_as_stl(data)
                except OSError as e:
                    self.sink.error(span, "E0652", f"the mesh cache cannot keep the STL of '{path}': {e}")
                    continue
                if converted is None:
                    self.sink.error(span, "E0440", f"MuJoCo refuses '{self.src.file}': mesh file '{path}' "
                                    "is not a .msh file (its sizes do not match its header)")
                    continue
                self.mesh_paths[mesh.name] = (uri[:-4] + ".stl", converted)
            else:
                self.mesh_paths[mesh.name] = (uri, path)

    def gather_other_files(self, spec: Any) -> None:
        """The files MuJoCo's compiler would read besides the meshes: textures, height fields
        and skins. The robot holds none of them, but MuJoCo reads them, so they follow the read
        rule and are handed to MuJoCo like the meshes."""
        uses = [("texture", t.name, spec.texturedir or "", f) for t in spec.textures
                for f in (t.file, *t.cubefiles) if f]
        uses += [(tag, item.name, spec.meshdir or "", item.file) for tag, items in
                 (("hfield", spec.hfields), ("skin", spec.skins)) for item in items if item.file]
        for tag, name, folder, file in uses:
            uri = file if os.path.isabs(file) else os.path.join(folder, file)
            path = self.base_dir / uri
            if why := self.resolver.refusal(path, self.base_dir):
                self.sink.error(self.span_of(tag, name=name), "E0650",
                                f"file '{file}' of <{tag}> '{name}' is not read: {why}")
            elif path.is_file():  # else MuJoCo says that it is missing
                self.assets[os.path.join(spec.modelfiledir, uri)] = path.read_bytes()

    def mujoco_error(self, text: str) -> None:
        """MuJoCo's error, at the element it names: on the line MuJoCo gives in the main file, at
        its start tag's column (at the attribute MuJoCo quotes, when it has it). In an included
        file MuJoCo gives line 0: there the first element of that tag that has the quoted
        attribute (else the first of that tag) in the included files is taken."""
        message = next((line for line in text.splitlines() if line.strip()), text)
        message = re.sub(r"^(XML )?Error: ", "", message.strip())
        line = int(m.group(1)) if (m := _LINE.search(text)) else 0
        tag = m.group(1) if (m := _ELEMENT.search(text)) else None
        attr = m.group(1) if (m := _ATTRIBUTE.search(message)) else None
        if line > 0:
            found = [(self.src, el) for el in self.src.root.iter() if isinstance(el.tag, str)
                     and (tag is None or el.tag == tag) and (el.sourceline or 0) >= line]
            found.sort(key=lambda item: item[1].sourceline or 0)
        else:
            found = [(src, el) for src in self.sources[1:] for el in src.root.iter(tag or "")
                     if tag is not None]
            found.sort(key=lambda item: attr is None or item[1].get(attr) is None)  # stable
        if found:
            src, el = found[0]
            span = src.span(el, attr if attr is not None and el.get(attr) is not None else None)
        else:
            span = Span(self.src.file, line, 1) if line > 0 else self.src.span(self.src.root)
        self.sink.error(span, "E0440", f"MuJoCo refuses '{self.src.file}': {message}")


def msh_as_stl(data: bytes) -> Path | None:
    """The binary STL of a MuJoCo `.msh` file (4 int32 counts: vertices, normals, texture
    coordinates, faces; then float32 positions, normals, coordinates and int32 faces), kept in
    the cache under its content's hash; None when the sizes do not match the header."""
    import hashlib

    from mpc.core.cache import cache_dir, load_entry, store_entry

    if len(data) < 16:
        return None
    nv, nn, nt, nf = np.frombuffer(data[:16], dtype="<i4")
    if min(nv, nn, nt, nf) < 0 or len(data) != 16 + 4 * (3 * nv + 3 * nn + 2 * nt + 3 * nf):
        return None
    entry = cache_dir("msh") / f"{hashlib.sha256(data).hexdigest()}.stl"
    if load_entry(entry)[0] is not None:
        return entry
    vertices = np.frombuffer(data, dtype="<f4", count=3 * nv, offset=16).reshape(-1, 3)
    faces = np.frombuffer(data, dtype="<i4", count=3 * nf, offset=16 + 4 * (3 * nv + 3 * nn + 2 * nt))
    faces = faces.reshape(-1, 3)
    if faces.size and (faces.min() < 0 or faces.max() >= nv):
        return None
    triangles = vertices[faces]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    record["n"], record["v"] = normals, triangles
    entry.parent.mkdir(parents=True, exist_ok=True)
    store_entry(entry, b"mpc: from a MuJoCo .msh".ljust(80, b" ") + np.uint32(len(faces)).tobytes()
                + record.tobytes())
    return entry


def _fresh(name: str, taken: set[str]) -> str:
    """`name`, or `name_2`, `name_3`, … when it is taken; the result is taken from then on."""
    out = free_name(name, taken, first=2)
    taken.add(out)
    return out


def _X(pos: np.ndarray, quat: np.ndarray | None = None) -> np.ndarray:
    X = np.eye(4)
    X[:3, 3] = pos
    if quat is not None:
        X[:3, :3] = tf.quat_to_matrix(quat)
    return X


def _pose(X: np.ndarray) -> Pose | None:
    return None if np.array_equal(X, np.eye(4)) else matrix_pose(X)


def _vec(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


class _Builder:
    def __init__(self, spec: Any, model: Any, files: _Files) -> None:
        self.spec, self.m, self.files = spec, model, files
        self.unheld: Counter[str] = Counter()
        m = model
        # The names mpc makes (of unnamed elements, fixed joints, chain links, sites) never
        # take one the file gives: a taken name gets _2, _3, …
        self.link_taken = {"world", *(m.body(b).name for b in range(1, m.nbody))}
        self.joint_taken = {m.joint(j).name for j in range(m.njnt)}
        self.body_names = ["world"] + [m.body(b).name or _fresh(f"body{b}", self.link_taken)
                                       for b in range(1, m.nbody)]
        self.joint_names = [m.joint(j).name or _fresh(f"{self.body_names[m.jnt_bodyid[j]]}_joint{j}",
                                                      self.joint_taken) for j in range(m.njnt)]
        self.links: dict[str, Link] = {}
        self.joints: dict[str, Joint] = {}
        self.materials: dict[str, Material] = {}
        self.shift: dict[int, np.ndarray] = {}  # a body's IR frame in its MuJoCo frame
        self.ir_joint: dict[int, str] = {}  # MuJoCo joint id → IR joint name (hinge, slide)

    def robot(self) -> Robot:
        m = self.m
        top = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
        joints_of = {b: [j for j in range(m.njnt) if m.jnt_bodyid[j] == b] for b in range(m.nbody)}
        # One top body, welded or free, is the root, as a URDF's; else the world body is.
        floating = len(top) == 1 and [m.jnt_type[j] for j in joints_of[top[0]]] in ([_FREE], [])
        root = self.body_names[top[0]] if floating else "world"
        self.shift[0] = np.eye(4)
        if floating:  # the world body holds the scene (a floor), not the robot
            self.unheld["worldbody geom"] += int(m.body_geomnum[0])
            self.unheld["worldbody site"] += sum(1 for s in range(m.nsite) if m.site_bodyid[s] == 0)
        for b in range(0 if not floating else 1, m.nbody):
            self.body(b, joints_of[b], root_body=floating and b == top[0])
        self.sites(skip_world=floating)
        for name, mimic in self.mimics().items():
            self.joints[name] = replace(self.joints[name], mimic=mimic)
        robot = Robot(name=self.spec.modelname or self.files.src.file, root=root, links=self.links,
                     joints=self.joints, materials=self.materials, motors=self.motors(),
                     cut_joints=self.cut_joints(), poses=self.poses(),
                     span=self.files.src.lazy_span(self.files.src.root))
        for what, count in _MODEL_COUNTS.items():
            self.unheld[what] += int(getattr(m, count))
        if text := self.unheld_text():
            self.files.sink.warning(self.files.src.span(self.files.src.root), "W0440",
                                    f"'{self.files.src.file}' holds what mpc's robot model cannot: {text}; "
                                    "left out")
        return robot

    # -- bodies and joints ------------------------------------------------------------------

    def body(self, b: int, joints: list[int], root_body: bool) -> None:
        m, name = self.m, self.body_names[b]
        movable = [j for j in joints if m.jnt_type[j] in (_HINGE, _SLIDE)]
        for j in joints:
            if m.jnt_type[j] == _BALL:
                self.unheld["ball joint"] += 1
        anchor = _vec(m.jnt_pos[movable[-1]]) if movable else (0.0, 0.0, 0.0)
        self.shift[b] = _X(np.array(anchor))
        self.links[name] = Link(name=name, inertial=self.inertial(b), visuals=(), collisions=(),
                                span=self.files.spans("body").get(name))
        self.geoms(b)
        if b == 0 or root_body:
            return
        parent = int(m.body_parentid[b])
        X = tf.inverse(self.shift[parent]) @ _X(m.body_pos[b], m.body_quat[b])
        parent_link = self.body_names[parent]
        if any(m.jnt_type[j] == _FREE for j in joints):
            jname = _fresh(f"{name}_floating", self.joint_taken)
            self.joints[jname] = Joint(name=jname, type="floating", parent=parent_link, child=name,
                                       origin=_pose(X))
            return
        if not movable:
            jname = _fresh(f"{name}_fixed", self.joint_taken)
            self.joints[jname] = Joint(name=jname, type="fixed", parent=parent_link, child=name,
                                       origin=_pose(X))
            return
        previous = np.zeros(3)
        for k, j in enumerate(movable):
            jname = self.joint_names[j]
            child = name if k == len(movable) - 1 else _fresh(f"{name}__{jname}", self.link_taken)
            if child != name:
                self.links[child] = Link(name=child)
            X = X @ _X(m.jnt_pos[j] - previous)
            previous = np.array(m.jnt_pos[j])
            self.joints[jname] = self.joint(j, jname, parent_link, child, X)
            self.ir_joint[j] = jname
            parent_link, X = child, np.eye(4)

    def joint(self, j: int, name: str, parent: str, child: str, X: np.ndarray) -> Joint:
        m = self.m
        hinge, limited = m.jnt_type[j] == _HINGE, bool(m.jnt_limited[j])
        ref = float(m.qpos0[m.jnt_qposadr[j]])  # `ref`: the IR's zero is the pose the file draws
        effort = float(np.max(np.abs(m.jnt_actfrcrange[j]))) if m.jnt_actfrclimited[j] else 0.0
        if hinge and not limited:
            jtype, limit = "continuous", Limit(effort=effort, velocity=0.0)
        else:
            lower, upper = (float(m.jnt_range[j][0]) - ref, float(m.jnt_range[j][1]) - ref) if limited \
                else (-UNBOUNDED, UNBOUNDED)
            jtype, limit = ("revolute" if hinge else "prismatic"), Limit(lower=lower, upper=upper,
                                                                          effort=effort, velocity=0.0)
        dof = m.jnt_dofadr[j]
        damping, friction, armature = (float(a[dof])
                                       for a in (m.dof_damping, m.dof_frictionloss, m.dof_armature))
        dynamics = Dynamics(damping=damping, friction=friction) if damping or friction else None
        notes: dict[str, object] = {"armature": armature} if armature else {}
        if stiffness := float(m.jnt_stiffness[j]):  # a spring, kept as the SDF reader keeps one
            notes |= {"spring_stiffness": stiffness,
                      "spring_reference": float(m.qpos_spring[m.jnt_qposadr[j]]) - ref}
        return Joint(name=name, type=jtype, parent=parent, child=child, origin=_pose(X),
                     axis=_vec(m.jnt_axis[j]), limit=limit, dynamics=dynamics,
                     span=self.files.spans("joint").get(name),
                     annotations=notes)

    def inertial(self, b: int) -> Inertial | None:
        m = self.m
        if b == 0:
            return None
        X = tf.inverse(self.shift[b]) @ _X(m.body_ipos[b], m.body_iquat[b])
        d = m.body_inertia[b]
        return Inertial(mass=float(m.body_mass[b]), origin=matrix_pose(X), inertia=Inertia(
            ixx=float(d[0]), ixy=0.0, ixz=0.0, iyy=float(d[1]), iyz=0.0, izz=float(d[2])))

    # -- geoms ------------------------------------------------------------------------------

    def geoms(self, b: int) -> None:
        m = self.m
        link = self.links[self.body_names[b]]
        visuals, collisions = list(link.visuals), list(link.collisions)
        for g in range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]):
            kind = int(m.geom_type[g])
            if kind in _UNHELD_GEOMS:
                self.unheld[_UNHELD_GEOMS[kind]] += 1
                continue
            X = tf.inverse(self.shift[b]) @ _X(m.geom_pos[g], m.geom_quat[g])
            shapes = self.shapes(g, kind, X)
            if shapes is None:
                continue
            name = m.geom(g).name or f"{self.body_names[b]}_geom{g}"
            collides = bool(m.geom_contype[g] or m.geom_conaffinity[g])
            names = [name] if len(shapes) == 1 else [f"{name}_{i}" for i in range(len(shapes))]
            if collides:
                collisions += [Collision(geometry=s, origin=_pose(Xs), name=n)
                               for n, (s, Xs) in zip(names, shapes, strict=True)]
            if not collides or m.geom_group[g] != COLLISION_GROUP:
                material = self.material(g)
                names = [f"{n}_visual" for n in names] if collides else names  # MJCF names are unique
                visuals += [Visual(geometry=s, origin=_pose(Xs), name=n, material=material)
                            for n, (s, Xs) in zip(names, shapes, strict=True)]
        self.links[link.name] = Link(name=link.name, inertial=link.inertial, visuals=tuple(visuals),
                                     span=link.span,
                                     collisions=tuple(collisions))

    def shapes(self, g: int, kind: int, X: np.ndarray) -> list[tuple[Geometry, np.ndarray]] | None:
        m, size = self.m, self.m.geom_size[g]
        if kind == 2:
            return [(Sphere(radius=float(size[0])), X)]
        if kind == 5:
            return [(Cylinder(radius=float(size[0]), length=2 * float(size[1])), X)]
        if kind == 6:
            return [(Box(size=_vec(2 * size)), X)]
        if kind == 3:  # a capsule: its cylinder and its two end spheres
            ends = [X @ _X(np.array([0.0, 0.0, z])) for z in (size[1], -size[1])]
            return [(Cylinder(radius=float(size[0]), length=2 * float(size[1])), X),
                    *((Sphere(radius=float(size[0])), E) for E in ends)]
        mesh = int(m.geom_dataid[g])
        name = m.mesh(mesh).name
        if name not in self.files.mesh_paths:
            self.unheld["mesh without a file"] += 1
            return None
        uri, path = self.files.mesh_paths[name]
        source = MeshSource(uri=uri, path=path)  # a .msh file's: its STL in the cache
        # MuJoCo takes a file's vertex v to s ⊙ (Rᵀ (v − refpos)) (R: refquat), then moves it to
        # the mesh's centre of mass and principal axes (mesh_pos, mesh_quat). In the IR the scale
        # acts in the file's frame: s is permuted to it when R permutes the axes (else unheld).
        spec_mesh = self.spec.mesh(name)
        R = tf.quat_to_matrix(np.asarray(spec_mesh.refquat, dtype=float))
        scale = np.asarray(m.mesh_scale[mesh], dtype=float)
        in_file = R @ np.diag(scale) @ R.T
        if not np.allclose(in_file, np.diag(np.diag(in_file)), rtol=0, atol=1e-12):
            self.unheld["mesh scaled along axes its refquat turns"] += 1
            return None
        X_ref = np.eye(4)
        X_ref[:3, :3] = R.T
        X_ref[:3, 3] = -scale * (R.T @ np.asarray(spec_mesh.refpos, dtype=float))
        X_file = X @ tf.inverse(_X(m.mesh_pos[mesh], m.mesh_quat[mesh])) @ X_ref
        file_scale = _vec(scale[np.argmax(np.abs(R), axis=1)])  # exactly the numbers written
        return [(Mesh(source=source, scale=None if file_scale == (1.0, 1.0, 1.0) else file_scale), X_file)]

    def material(self, g: int) -> str | None:
        m = self.m
        mat = int(m.geom_matid[g])
        rgba = tuple(float(v) for v in (m.mat_rgba[mat] if mat >= 0 else m.geom_rgba[g]))
        name = (m.material(mat).name or f"material{mat}") if mat >= 0 else \
            "rgba_" + "_".join(f"{v:g}" for v in rgba)
        if name not in self.materials:
            self.materials[name] = Material(name=name, rgba=rgba)  # type: ignore[arg-type]
        return name

    # -- the rest ---------------------------------------------------------------------------

    def sites(self, skip_world: bool) -> None:
        m = self.m
        for s in range(m.nsite):
            b = int(m.site_bodyid[s])
            if skip_world and b == 0:
                continue
            site = m.site(s).name
            wanted = f"{site}_site" if site in self.link_taken else site or f"{self.body_names[b]}_site{s}"
            name = _fresh(wanted, self.link_taken)
            X = tf.inverse(self.shift[b]) @ _X(m.site_pos[s], m.site_quat[s])
            self.links[name] = Link(name=name, span=self.files.spans("site").get(site))
            jname = _fresh(f"{name}_fixed", self.joint_taken)
            self.joints[jname] = Joint(name=jname, type="fixed", parent=self.body_names[b], child=name,
                                       origin=_pose(X))

    def motors(self) -> dict[str, Motor]:
        m, out = self.m, {}
        for a in range(m.nu):
            j = int(m.actuator_trnid[a][0])
            if m.actuator_trntype[a] != 0 or j not in self.ir_joint:  # 0: a joint
                self.unheld["actuator not on a hinge or slide"] += 1
                continue
            name = m.actuator(a).name or f"actuator{a}"
            gain, bias = m.actuator_gainprm[a], m.actuator_biasprm[a]
            settings: dict[str, object] = {"type": "force", "gear": float(m.actuator_gear[a][0])}
            if m.actuator_biastype[a] == 1 and bias[1] == -gain[0] and gain[0] != 0:
                settings = {"type": "position", "p": float(gain[0]), "d": float(-bias[2])}
            elif m.actuator_biastype[a] == 1 and bias[2] == -gain[0] and gain[0] != 0:
                settings = {"type": "velocity", "d": float(gain[0])}
            if m.actuator_ctrllimited[a]:
                settings["minValue"], settings["maxValue"] = (float(v) for v in m.actuator_ctrlrange[a])
            if m.actuator_forcelimited[a]:
                settings["maxEffort"] = float(np.max(np.abs(m.actuator_forcerange[a])))
            out[name] = Motor(name=name, joint=self.ir_joint[j], settings=settings)
        return out

    def world_frames(self) -> dict[int, np.ndarray]:
        """Each body's IR frame in the world at qpos0."""
        mujoco = _mujoco()
        data = mujoco.MjData(self.m)
        mujoco.mj_kinematics(self.m, data)
        return {b: _X(data.xpos[b], data.xquat[b]) @ self.shift[b] for b in range(self.m.nbody)}

    def cut_joints(self) -> dict[str, CutJoint]:
        m, out = self.m, {}
        if not m.neq:
            return out
        W = self.world_frames()
        for e in range(m.neq):
            kind, objtype = int(m.eq_type[e]), int(m.eq_objtype[e])
            if self.mimic_of(e) is not None:
                continue  # a joint's mimic (`mimics`)
            if kind not in (0, 1) or objtype != 1:  # connect and weld between bodies
                self.unheld["equality other than a connect or weld of bodies"] += 1
                continue
            b1, b2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
            name = m.equality(e).name or f"equality{e}"
            parent, child = self.body_names[b1], self.body_names[b2]
            X_PC = tf.inverse(W[b1]) @ W[b2]
            # The constrained point: the anchor on body1 (connect), on body2 (weld).
            anchor = _X(m.eq_data[e][0:3]) if kind == 0 else _X(m.eq_data[e][3:6])
            X_CJ = tf.inverse(X_PC) @ tf.inverse(self.shift[b1]) @ anchor if kind == 0 \
                else tf.inverse(self.shift[b2]) @ anchor
            jo = matrix_pose(X_CJ)
            out[name] = CutJoint(name=name, type="ball" if kind == 0 else "fixed", parent=parent,
                                 child=child, origin=matrix_pose(X_PC),
                                 annotations={"joint_origin": {"xyz": list(jo.xyz), "rpy": list(jo.rpy)}})
        return out

    def mimic_of(self, e: int) -> tuple[str, Mimic] | None:
        """A joint equality that is linear (polycoef's quadratic and higher terms 0) between two
        joints of the robot → (the follower, its mimic), as the MJCF export writes a mimic; else
        None. The IR's zero is each joint's `ref`: the offset is moved by both refs."""
        m = self.m
        if int(m.eq_type[e]) != _EQ_JOINT:  # its objtype is not set in the compiled model
            return None
        j1, j2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
        c = m.eq_data[e][:5]
        if j1 not in self.ir_joint or j2 not in self.ir_joint or any(c[2:5]):
            return None
        ref1, ref2 = (float(m.qpos0[m.jnt_qposadr[j]]) for j in (j1, j2))
        return self.ir_joint[j1], Mimic(joint=self.ir_joint[j2], multiplier=float(c[1]),
                                        offset=float(c[0]) + float(c[1]) * ref2 - ref1)

    def mimics(self) -> dict[str, Mimic]:
        return dict(found for e in range(self.m.neq) if (found := self.mimic_of(e)) is not None)

    def poses(self) -> dict[str, dict[str, float]]:
        m, out = self.m, {}
        for k in range(m.nkey):
            name = m.key(k).name or f"key{k}"
            out[name] = {jname: float(m.key_qpos[k][m.jnt_qposadr[j]] - m.qpos0[m.jnt_qposadr[j]])
                         for j, jname in self.ir_joint.items()}
        return out

    def unheld_text(self) -> str:
        return ", ".join(f"{what} ×{n}" for what, n in sorted(self.unheld.items()) if n)
