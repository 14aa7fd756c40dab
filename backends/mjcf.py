"""ir.Robot → canonical MJCF (MuJoCo's format): `<out>/mjcf/<robot>.xml`, meshes (stl or obj)
in `<out>/meshes/<fmt>/`. It does not read MJCF, nor fix inertias, nor write what MJCF cannot
hold (fragments, sensors, velocity limits, …): one W0500 names those.

The root link is a body fixed to the world (no joint), as in Pinocchio with a fixed base;
a free-floating robot needs a `floating` joint in the IR. A root link named `world` is
MuJoCo's world body itself. Bodies nest depth-first, children by joint name; a body sits at
its joint's origin, the joint at the body's origin, the axis as in URDF. revolute → hinge with
range, continuous → hinge, prismatic → slide, fixed → no joint (a welded body), floating →
freejoint (its body hoisted to the world; deeper down: three slides and a ball), planar → two
slides and a hinge. Mimic → `<equality><joint>` with joint1 = offset + multiplier·joint2 (polycoef);
motors → the actuators their types name, and the export's `actuators` option for the joints
without one (backends/mjcf_actuation.py); named poses → `<keyframe>`; which links collide →
contype/conaffinity from the bitmasks, or `<contact><exclude>` (backends/mjcf_contacts.py);
visuals group 2 with their material colours (DAE files split per material, backends/dae_colours.py),
collisions group 3; `scene: true` → a scene file (backends/mjcf_scene.py). Cut joints (loop
closures) → equalities between two sites, one on each side
(see `cut_sites`): `<weld>` for fixed ones, `<connect>` for ball ones, two `<connect>`s along
the axis for a revolute or continuous one whose axis is known, one `<connect>` (a ball joint)
for other rotational ones; translational ones are left out (W0500). Sites, not `anchor`: with
body1/body2/anchor MuJoCo takes body2's point from qpos0, so a closure whose two sides do not
coincide at q = 0 (or that sits off its child's origin) would close elsewhere than the source's.

Inertia: `diaginertia` in the principal frame (`quat`), diagonalised here, so that MuJoCo
checks exactly the numbers written (eigenvalues within 1e-12 of the largest are round-off,
written as 0); `fullinertia` would refuse a zero inertia (a massless link) even on a welded
body. `check` reports (E0504) what MuJoCo would refuse or change. `<compiler>` pins every
setting that could change an inertia silently: angle radian (URDF's unit); autolimits (a range
limits its joint); inertiafromgeom false (else a link without inertial gets its geoms' mass);
balanceinertia false (else A + B < C is averaged away); boundmass and boundinertia 0 (no
floor; 0 still clamps negatives, hence `check`); fusestatic false (else welded bodies merge
and the root joins the world, its mass lost); discardvisual false (keep visual geoms).
Meshes get inertia="shell": MuJoCo computes every mesh's inertia, though none is used here,
and refuses a mesh of too small a volume (open or flat visual meshes).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Collection, Iterator
from pathlib import Path

import numpy as np

from mpc.backends import holds, meshes, mjcf_actuation, mjcf_contacts, mjcf_scene, xml_escape
from mpc.backends.dae_colours import coloured
from mpc.backends.float_formats import MJCF_KEYS, Formats
from mpc.backends.xml import fmt_float, fmt_floats, write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.core.names import free_name
from mpc.core.numbers import EPSILON
from mpc.core.span import Span
from mpc.ir import transforms as tf
from mpc.ir.extras import CutJoint
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere
from mpc.ir.kinematics import matrix_pose, pose_matrix
from mpc.ir.physical import TOO_LARGE, principal_moments
from mpc.ir.program import MjcfExport
from mpc.ir.robot import Collision, Inertial, Joint, Link, Pose, Robot, Visual
from mpc.ir.tree import child_joints, depth_first

__all__ = ["MAX_BODY_DEPTH", "body_depth", "check", "cut_axis", "cut_sites", "emit", "left_out", "principal",
           "to_string"]

Quat = tuple[float, float, float, float]
# MuJoCo parses MJCF with tinyxml2, which refuses elements nested deeper than 500: <mujoco>,
# <worldbody>, the bodies and their <geom>s leave room for 496 nested bodies.
MAX_BODY_DEPTH = 496
Pairs = list[tuple[str, str | None]]
MJMINVAL = 1e-15  # MuJoCo's mjMINVAL: the least mass and inertia of a moving body
IND = "  "
VISUAL_GROUP, COLLISION_GROUP = 2, 3  # Menagerie's geom groups: visuals drawn by default, collisions hidden
COMPILER: Pairs = [("angle", "radian"), ("autolimits", "true"), ("inertiafromgeom", "false"),
            ("balanceinertia", "false"), ("boundmass", "0"), ("boundinertia", "0"),
            ("fusestatic", "false"), ("discardvisual", "false")]


def _attrs(pairs: Pairs) -> str:
    return "".join(f' {k}="{xml_escape.attribute(v)}"' for k, v in pairs if v is not None)


def _quat_rpy(rpy: tuple[float, float, float]) -> Quat:
    """(w, x, y, z) of URDF's fixed-axis rpy, R = Rz·Ry·Rx; w ≥ 0."""
    cr, sr = math.cos(rpy[0] / 2), math.sin(rpy[0] / 2)
    cp, sp = math.cos(rpy[1] / 2), math.sin(rpy[1] / 2)
    cy, sy = math.cos(rpy[2] / 2), math.sin(rpy[2] / 2)
    q = (cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr,
         cy * sp * cr + sy * cp * sr, sy * cp * cr - cy * sp * sr)
    return q if q[0] >= 0 else (-q[0], -q[1], -q[2], -q[3])


def _pose_pairs(pose: Pose | None) -> Pairs:
    """pos and quat of a pose, each left out when it is the identity (MJCF's default)."""
    if pose is None:
        return []
    q = _quat_rpy(pose.rpy)
    return [("pos", fmt_floats(pose.xyz) if any(pose.xyz) else None),
            ("quat", fmt_floats(q) if q != (1.0, 0.0, 0.0, 0.0) else None)]


def principal(inertial: Inertial) -> tuple[tuple[float, float, float], Quat]:
    """The principal moments and the principal frame (in the link frame) of an inertial."""
    i = inertial.inertia
    rpy = inertial.origin.rpy if inertial.origin is not None else (0.0, 0.0, 0.0)
    if i.ixy == 0 and i.ixz == 0 and i.iyz == 0:
        return (i.ixx, i.iyy, i.izz), _quat_rpy(rpy)
    I_c = np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])
    w, V = np.linalg.eigh(I_c)
    if np.linalg.det(V) < 0:
        V[:, 2] = -V[:, 2]
    big = float(np.max(np.abs(w)))
    d = tuple(0.0 if abs(x) <= 1e-12 * big else float(x) for x in w)
    return d, tf.matrix_to_quat(tf.rpy_to_matrix(rpy) @ V)  # type: ignore[return-value]


def unusable_inertial(inertial: Inertial) -> str | None:
    """Why MuJoCo cannot be given this inertial at all, or None: a number that is not finite
    (a definition's `.inf`, or a product that overflowed), or an inertia so large that its
    principal moments are not finite numbers (eigh overflows, or does not converge)."""
    i = inertial.inertia
    xyz = inertial.origin.xyz if inertial.origin is not None else (0.0, 0.0, 0.0)
    numbers = (inertial.mass, i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz, *xyz)
    if not all(math.isfinite(x) for x in numbers):
        return "its mass, inertia or centre of mass holds a number that is not finite"
    return TOO_LARGE if principal_moments(i) is None else None


def _mass_ok(inertial: Inertial | None) -> bool:
    return (inertial is not None and unusable_inertial(inertial) is None and inertial.mass >= MJMINVAL
            and min(principal(inertial)[0]) >= MJMINVAL)


def passes_through(robot: Robot, link: Link, joint: Joint | None, children: list[Joint]) -> Joint | None:
    """The one joint below `link` when the link only passes motion on: it moves by a 1-dof
    `joint`, has no mass, shapes or loop closure, and one 1-dof child joint that does not turn
    the frame (an MJCF input's body with several joints, backends/mjcf_reader.py). MuJoCo refuses
    a moving body without mass, so the link's joint goes into its child's body (MuJoCo applies
    a body's joints in order); else None."""
    if not _one_dof(joint) or link.visuals or link.collisions or len(children) != 1 \
            or not _one_dof(children[0]) or (children[0].origin is not None and any(children[0].origin.rpy)):
        return None
    inertial = link.inertial
    if inertial is not None and (inertial.mass != 0 or any(principal(inertial)[0])):
        return None
    if any(link.name in (c.parent, c.child) for c in robot.cut_joints.values()):
        return None
    return children[0]


def check(robot: Robot, sink: Sink, span: Span, only: Collection[str] | None = None) -> bool:
    """Report (E0504) each link whose mass properties MuJoCo would refuse or change, by its
    rules: mass and principal moments not negative (MuJoCo clamps them to 0), moments
    satisfying A + B ≥ C (on every body), and a moving body's mass and moments at least
    mjMINVAL unless a body welded below it has both. only: the links to report (`mpc
    check`: those the finished robot keeps)."""
    children, ok = child_joints(robot), True
    moving = {j.child for j in robot.joints.values() if j.type != "fixed"}
    parent_joint = {j.child: j for j in robot.joints.values()}
    order = [link for _, link in depth_first(robot)]
    welded_mass: dict[str, bool] = {}  # a link welded below it carries mass; from the leaves up
    for link in reversed(order):
        welded_mass[link] = any(j.type == "fixed" and (_mass_ok(robot.links[j.child].inertial)
                                                       or welded_mass[j.child])
                                for j in children.get(link, []))

    for link in order:
        inertial = robot.links[link].inertial
        if link == robot.root == "world":
            continue
        problems = []
        unusable = unusable_inertial(inertial) if inertial is not None else None
        if unusable is not None:
            problems.append(unusable)
        elif inertial is not None:
            d, _ = principal(inertial)
            a, b, c = sorted(d)
            if inertial.mass < 0:
                problems.append(f"its mass {fmt_float(inertial.mass)} is negative")
            if a < 0:
                problems.append(f"its inertia is not positive semi-definite (principal moment "
                                f"{fmt_float(a)})")
            elif a + b < c:
                problems.append(f"its principal moments violate A + B ≥ C ({fmt_float(a)} + "
                                f"{fmt_float(b)} < {fmt_float(c)})")
        if link in moving and not _mass_ok(inertial) and not welded_mass[link] and passes_through(
                robot, robot.links[link], parent_joint.get(link), children.get(link, [])) is None:
            problems.append(f"it moves but its mass or a principal moment is below mjMINVAL "
                            f"({MJMINVAL:g}) and no link welded to it carries mass")
        if problems and (only is None or link in only):
            sink.error(robot.links[link].span or span, "E0504", f"link '{link}' has mass properties "
                       f"MuJoCo refuses or changes: {'; '.join(problems)}",
                       hint="set `correct_inertials: true` on the export to make it physical, or fix its "
                       "inertial",
                       notes=((span, "the export that would write it"),) if robot.links[link].span else ())
            ok = False
    return ok


def _limits(joint: Joint) -> tuple[float, float] | None:
    """(lower, upper) as URDF means them (a missing one is 0), or None without any."""
    lim = joint.limit
    if joint.type not in ("revolute", "prismatic") or lim is None:
        return None
    if lim.lower is None and lim.upper is None:
        return None
    return (lim.lower or 0.0, lim.upper or 0.0)


# Cut joint types MJCF closes: a weld, connects (points) for the rotational ones.
_POINT_CUTS = ("ball", "revolute", "continuous", "universal", "revolute2")
_HINGE_CUTS = ("revolute", "continuous")
AXIS_POINT = 0.1  # m along a hinge closure's axis: its second connect's point


def cut_axis(cut: CutJoint) -> np.ndarray | None:
    """A revolute closure's axis in the child link's frame (`axis`, as an SDF input gives it)."""
    axis = cut.annotations.get("axis") if cut.type in _HINGE_CUTS else None
    if not isinstance(axis, list | tuple) or len(axis) != 3:
        return None
    a = np.asarray(axis, dtype=float)
    return a / np.linalg.norm(a) if np.all(np.isfinite(a)) and np.linalg.norm(a) > 0 else None


def cut_sites(cut: CutJoint) -> list[tuple[str, Pose, Pose]]:
    """The points where a cut joint closes its loop: (suffix, pose on the parent, pose on the
    child). The joint frame sits on the child at `joint_origin` (an SDF input's), else at the
    child's origin; on the parent it is the same frame at the zero configuration (origin ∘
    joint frame), as in Pinocchio's constraint model (checks/dynamics_model.py). A hinge
    closure with a known axis has a second point, AXIS_POINT along the axis."""
    jo = cut.annotations.get("joint_origin")
    X_CJ = np.eye(4)
    if isinstance(jo, dict):
        X_CJ = pose_matrix(Pose(tuple(jo.get("xyz", (0.0, 0.0, 0.0))),  # type: ignore[arg-type]
                                tuple(jo.get("rpy", (0.0, 0.0, 0.0)))))  # type: ignore[arg-type]
    X_PJ = pose_matrix(cut.origin) @ X_CJ
    out = [("", matrix_pose(X_PJ), matrix_pose(X_CJ))]
    axis = cut_axis(cut)
    if axis is not None:
        shift = np.eye(4)
        shift[:3, 3] = AXIS_POINT * (X_CJ[:3, :3].T @ axis)  # the axis, in the joint frame
        out.append(("_axis", matrix_pose(X_PJ @ shift), matrix_pose(X_CJ @ shift)))
    return out


def _one_dof(joint: Joint | None) -> bool:
    return joint is not None and joint.type in ("revolute", "continuous", "prismatic")


def left_out(robot: Robot, actuators: str = "motors") -> list[str]:
    """What the robot holds that this MJCF does not: fragments, sensors, velocity limits, …
    (the table `CANNOT_HOLD`, read by backends/holds.py); `actuators`: the export's option."""
    return holds.left_out(robot, CANNOT_HOLD, actuators=actuators)


def _shapes(robot: Robot) -> list[Visual | Collision]:
    return [s for lk in robot.links.values() for s in (*lk.visuals, *lk.collisions)]


def _elements(robot: Robot) -> tuple[Link | Joint | Visual | Collision, ...]:
    return (*robot.links.values(), *robot.joints.values(), *_shapes(robot))


def _beyond_colour(robot: Robot) -> int:
    """The materials with a texture or a property MJCF's `rgba` cannot say."""
    inline = [v.inline_material for lk in robot.links.values() for v in lk.visuals]
    return sum(m.texture is not None or m.normal_texture is not None or bool(m.annotations) or any(
        getattr(m, k) is not None for k in ("ambient", "specular", "emissive", "shininess", "transparency"))
        for m in (*robot.materials.values(), *(m for m in inline if m is not None)))


def _mimic_without_one_dof(robot: Robot, joint: Joint) -> bool:
    mimic = joint.mimic
    return mimic is not None and not (_one_dof(joint) and _one_dof(robot.joints.get(mimic.joint)))


def _uncloseable_cuts(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    for c in sorted(robot.cut_joints.values(), key=lambda c: c.name):
        if c.type != "fixed" and c.type not in _POINT_CUTS:
            yield holds.Named(f"{c.type} cut joint '{c.name}' (MJCF has no equality for it)"), 1


def _element_tags(robot: Robot, options: holds.Options) -> Iterator[tuple[holds.Phrase, int]]:
    """The extra elements of the robot, its links, joints, shapes and inertials, by tag."""
    inertials = [lk.inertial for lk in robot.links.values() if lk.inertial is not None]
    tags = Counter(f.tag for f in (*robot.fragments, *(f for el in (*_elements(robot), *inertials)
                                                       for f in el.extras)))
    for tag, n in sorted(tags.items()):
        yield holds.noun(f"<{tag}> element"), n


def _world_mass(robot: Robot, options: holds.Options) -> bool:
    inertial = robot.links[robot.root].inertial
    return robot.root == "world" and inertial is not None and inertial.mass != 0


_C = holds.Counted
# What MJCF cannot hold, in the order W0500 names it.
CANNOT_HOLD: tuple[holds.Tally, ...] = (
    holds.count(_C("sensor", "sensors"), lambda r, o: len(r.sensors)),
    holds.count(_C("pose value of a joint without one degree of freedom", "pose values of joints without one "
                   "degree of freedom"), lambda r, o: sum(not _one_dof(r.joints.get(j))
                                                          for p in r.poses.values() for j in p)),
    holds.count(_C("submechanism", "submechanisms"), lambda r, o: len(r.submechanisms)),
    holds.count(_C("annotation category", "annotation categories"), lambda r, o: len(r.annotations)),
    holds.count(_C("annotated link or joint", "annotated links and joints"), lambda r, o: sum(
        bool(e.annotations) for e in (*r.links.values(), *r.joints.values()))),
    holds.count(_C("annotated visual or collision", "annotated visuals and collisions"), lambda r, o: sum(
        bool(s.annotations) for s in _shapes(r))),
    holds.count(_C("joint velocity limit", "joint velocity limits"), lambda r, o: sum(
        j.limit is not None and j.limit.velocity is not None for j in r.joints.values())),
    holds.count(_C("joint calibration", "joint calibrations"), lambda r, o: sum(
        j.calibration is not None for j in r.joints.values())),
    holds.count(_C("safety controller", "safety controllers"), lambda r, o: sum(
        j.safety_controller is not None for j in r.joints.values())),
    holds.count(_C("empty position range (lower ≥ upper)", "empty position ranges (lower ≥ upper)"),
                lambda r, o: sum((x := _limits(j)) is not None and x[0] >= x[1] for j in r.joints.values())),
    holds.count(_C("material texture or property beyond colour", "material textures or properties beyond "
                   "colour"), lambda r, o: _beyond_colour(r)),
    holds.count(_C("name of a visual or collision used twice", "names of visuals or collisions used twice"),
                lambda r, o: sum(n for n in Counter(s.name for s in _shapes(r) if s.name is not None).values()
                                 if n > 1)),
    holds.count(_C("attribute URDF does not define", "attributes URDF does not define"), lambda r, o: sum(
        len(e.extra_attrs) for e in _elements(r))),
    holds.count(_C("mimic of or by a joint without one degree of freedom", "mimics of or by joints without "
                   "one degree of freedom"), lambda r, o: sum(_mimic_without_one_dof(r, j)
                                                               for j in r.joints.values())),
    *mjcf_actuation.CANNOT_HOLD,
    holds.count(_C("cut joint constraint axis", "cut joint constraint axes"), lambda r, o: sum(
        len(c.constraint_axes) for c in r.cut_joints.values())),
    holds.count(_C("rotational cut joint's axis (without one, a connect is a ball joint)",
                   "rotational cut joints' axes (without one, a connect is a ball joint)"), lambda r, o: sum(
        c.type in _POINT_CUTS and c.type != "ball" and cut_axis(c) is None for c in r.cut_joints.values())),
    _uncloseable_cuts,
    _element_tags,
    holds.named(holds.Named("the mass of the root link 'world' (MuJoCo's world body has none)"), _world_mass),
    holds.named(holds.Named("the submechanisms file"), lambda r, o: bool(r.submechanisms_file)),
)


class _Writer:
    def __init__(self, robot: Robot, mesh_name: Callable[[Mesh], str], formats: Formats | None = None,
                 enforce_zero: bool = False, actuators: str = "motors") -> None:
        self.robot, self.mesh_name, self.formats = robot, mesh_name, formats
        self.enforce_zero, self.actuator_mode = enforce_zero, actuators
        self.out: list[str] = []
        self.children = child_joints(robot)
        self.assets: dict[tuple[str, str | None], str] = {}  # (file, scale) → asset name
        self.materials: dict[tuple[str, str], str] = {}  # (material name, rgba) → asset name
        # The qpos vector as the joints are written (MuJoCo's order): (joint name or None, value at q0).
        self.qpos: list[tuple[str | None, float]] = []
        self.bitmasks = mjcf_contacts.uses_bitmasks(robot)
        shapes = [s for lk in robot.links.values() for s in (*lk.visuals, *lk.collisions)]
        counts = Counter(s.name for s in shapes)
        self.unique_names = {n for n, c in counts.items() if c == 1 and n is not None}
        # A free joint must be at the top level: its body is hoisted to the world (the root
        # body sits at the identity, so the joint origin stays right).
        self.hoisted = {j.name for j in self.children.get(robot.root, [])
                        if j.type == "floating" and robot.root != "world"}
        # The sites the loop closures join, by link: (name, pose in the link). Names end in
        # _parent, _child, _parent_axis, _child_axis, so two cut joints' sites never clash.
        self.sites: dict[str, list[tuple[str, Pose]]] = {}
        for cut in self._written_cuts():
            for suffix, on_parent, on_child in cut_sites(cut):
                self.sites.setdefault(cut.parent, []).append((f"{cut.name}_parent{suffix}", on_parent))
                self.sites.setdefault(cut.child, []).append((f"{cut.name}_child{suffix}", on_child))

    def _written_cuts(self) -> list[CutJoint]:
        cuts = [self.robot.cut_joints[n] for n in sorted(self.robot.cut_joints)]
        return [c for c in cuts if c.type == "fixed" or c.type in _POINT_CUTS]

    def attrs(self, pairs: Pairs) -> str:
        if self.enforce_zero:  # also the numbers computed here (quaternions, principal frames)
            pairs = [(k, _zeroed(v) if k in MJCF_KEYS else v) for k, v in pairs]
        if self.formats is not None:  # float_fmt_dict (backends/float_formats.py)
            pairs = [(k, self.formats(k, v)) for k, v in pairs]
        return _attrs(pairs)

    def leaf(self, depth: int, tag: str, pairs: Pairs) -> None:
        self.out.append(f"{IND * depth}<{tag}{self.attrs(pairs)}/>")

    def asset(self, mesh: Mesh) -> str:
        key = (self.mesh_name(mesh), fmt_floats(mesh.scale) if mesh.scale is not None else None)
        if key not in self.assets:
            stem = key[0].rsplit("/", 1)[-1].rsplit(".", 1)[0]
            self.assets[key] = free_name(stem, set(self.assets.values()))
        return self.assets[key]

    def material(self, name: str, rgba: tuple[float, float, float, float]) -> str:
        """The asset name of a material colour: its own name, made unique when two colours share it."""
        key = (name or "material", fmt_floats(rgba))  # MuJoCo refuses an empty name
        if key not in self.materials:
            self.materials[key] = free_name(key[0], set(self.materials.values()))
        return self.materials[key]

    def _emit_geom(self, depth: int, shape: Visual | Collision) -> None:
        g = shape.geometry
        pairs: Pairs = [("name", shape.name if shape.name in self.unique_names else None)]
        match g:
            case Box():
                pairs += [("type", "box"), ("size", fmt_floats([s / 2 for s in g.size]))]
            case Cylinder():
                pairs += [("type", "cylinder"), ("size", fmt_floats([g.radius, g.length / 2]))]
            case Sphere():
                pairs += [("type", "sphere"), ("size", fmt_float(g.radius))]
            case Mesh():
                pairs += [("type", "mesh"), ("mesh", self.asset(g))]
        pairs += _pose_pairs(shape.origin)
        if isinstance(shape, Visual):
            m = shape.inline_material or self.robot.materials.get(shape.material or "")
            material = self.material(m.name, m.rgba) if m is not None and m.rgba is not None else None
            pairs += [("contype", "0"), ("conaffinity", "0"), ("group", str(VISUAL_GROUP)),
                      ("material", material)]
        else:
            bits = str(shape.bitmask) if shape.bitmask is not None else None
            pairs += [("contype", bits), ("conaffinity", bits), ("group", str(COLLISION_GROUP))]
        self.leaf(depth, "geom", pairs)

    def _emit_inertial(self, depth: int, inertial: Inertial) -> None:
        d, q = principal(inertial)
        xyz = inertial.origin.xyz if inertial.origin is not None else (0.0, 0.0, 0.0)
        self.leaf(depth, "inertial", [("pos", fmt_floats(xyz)),
                                      ("quat", fmt_floats(q) if q != (1.0, 0.0, 0.0, 0.0) else None),
                                      ("mass", fmt_float(inertial.mass)), ("diaginertia", fmt_floats(d))])

    def _emit_joint(self, depth: int, joint: Joint, top: bool, pos: np.ndarray | None = None) -> None:
        axis = joint.axis or (1.0, 0.0, 0.0)
        dyn = joint.dynamics
        at = ("pos", fmt_floats([float(c) for c in pos])) if pos is not None and pos.any() else ("pos", None)
        common: Pairs = [
            ("damping", fmt_float(dyn.damping) if dyn and dyn.damping else None),
            ("frictionloss", fmt_float(dyn.friction) if dyn and dyn.friction else None)]
        effort = joint.limit.effort if joint.limit is not None else None
        if effort:
            common.append(("actuatorfrcrange", fmt_floats([-abs(effort), abs(effort)])))
        if joint.type in ("revolute", "continuous", "prismatic"):
            r = _limits(joint)
            rng: Pairs = [("limited", "true"), ("range", fmt_floats(r))] if r and r[0] < r[1] else []
            kind = "slide" if joint.type == "prismatic" else "hinge"
            self.leaf(depth, "joint", [("name", joint.name), ("type", kind), at, ("axis", fmt_floats(axis)),
                                       *rng, *common])
            self.qpos.append((joint.name, 0.0))
        elif joint.type == "floating" and top:
            self.leaf(depth, "freejoint", [("name", joint.name)])
            origin = joint.origin or Pose()
            self.qpos += [(None, x) for x in (*origin.xyz, *_quat_rpy(origin.rpy))]
        elif joint.type in ("floating", "planar"):
            n = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
            e1 = np.eye(3)[int(np.argmin(np.abs(n)))]
            e1 = (e1 - (e1 @ n) * n) / np.linalg.norm(e1 - (e1 @ n) * n)
            dirs = (("x", (1.0, 0.0, 0.0)), ("y", (0.0, 1.0, 0.0)), ("z", (0.0, 0.0, 1.0))) \
                if joint.type == "floating" else (("x", tuple(e1)), ("y", tuple(np.cross(n, e1))))
            for suffix, d in dirs:
                self.leaf(depth, "joint", [("name", f"{joint.name}_{suffix}"), ("type", "slide"),
                                           ("axis", fmt_floats([float(c) for c in d])), *common])
            last = ("ball", None) if joint.type == "floating" else ("hinge", fmt_floats(axis))
            self.leaf(depth, "joint", [("name", f"{joint.name}_rot"), ("type", last[0]),
                                       ("axis", last[1]), *common])
            rot = (1.0, 0.0, 0.0, 0.0) if joint.type == "floating" else (0.0,)
            self.qpos += [(None, 0.0)] * len(dirs) + [(None, x) for x in rot]

    def _emit_body(self, depth: int, joint: Joint | None, link: Link, top: bool) -> None:
        """The link's body at `joint`'s origin (inertial, joint, geoms), then the bodies below it,
        depth-first. A loop, not recursion: a chain of thousands of links is a valid model."""
        todo: list[tuple[int, Joint | None, Link] | str] = [(depth, joint, link)]
        while todo:
            item = todo.pop()
            if isinstance(item, str):  # a closing tag
                self.out.append(item)
                continue
            depth, joint, link = item
            # Links that only pass motion on join the body below them, their joints with it.
            chain: list[Joint] = []  # the joints below `joint` that join its body
            X = pose_matrix(joint.origin if joint is not None else None)
            while (below := passes_through(self.robot, link, chain[-1] if chain else joint,
                                           self._child_bodies(link))) is not None:
                chain.append(below)
                X = X @ pose_matrix(below.origin)
                link = self.robot.links[below.child]
            pose = _pose_pairs(matrix_pose(X) if chain else joint.origin if joint is not None else None)
            self.out.append(f"{IND * depth}<body{self.attrs([('name', link.name), *pose])}>")
            d = depth + 1
            if link.inertial is not None:
                self._emit_inertial(d, link.inertial)
            anchor = np.zeros(3)  # each joint's place in the body: minus the origins below it
            anchors = []
            for j in reversed(chain):
                anchors.append(anchor.copy())
                anchor = anchor - np.asarray(j.origin.xyz if j.origin is not None else (0.0, 0.0, 0.0))
            if joint is not None:
                self._emit_joint(d, joint, top, anchor if chain else None)
            for j, at in zip(chain, reversed(anchors), strict=True):
                self._emit_joint(d, j, top, at)
            self._emit_geoms(d, link)
            todo.append(f"{IND * depth}</body>")
            todo.extend((d, j, self.robot.links[j.child]) for j in reversed(self._child_bodies(link)))

    def _emit_geoms(self, depth: int, link: Link) -> None:
        """The link's geoms, then its sites."""
        for shape in (*link.visuals, *link.collisions):
            self._emit_geom(depth, shape)
        for name, pose in self.sites.get(link.name, []):
            self.leaf(depth, "site", [("name", name), *_pose_pairs(pose), ("group", "5")])

    def _child_bodies(self, link: Link) -> list[Joint]:
        """The joints to the bodies nested in the link's body (hoisted ones are the world's)."""
        return [j for j in self.children.get(link.name, []) if j.name not in self.hoisted]

    def _emit_worldbody(self) -> None:
        root = self.robot.links[self.robot.root]
        self.out.append(f"{IND}<worldbody>")
        if root.name == "world":  # the URDF convention for the fixed frame: MuJoCo's world body
            self._emit_geoms(2, root)
            for j in self._child_bodies(root):  # the children are bodies of the world
                self._emit_body(2, j, self.robot.links[j.child], top=True)
        else:
            self._emit_body(2, None, root, top=False)
            for name in sorted(self.hoisted):
                joint = self.robot.joints[name]
                self._emit_body(2, joint, self.robot.links[joint.child], top=True)
        self.out.append(f"{IND}</worldbody>")

    def _emit_equality(self, depth: int = 2) -> None:
        movable = {n for n, j in self.robot.joints.items() if _one_dof(j)}
        for name in sorted(movable):
            m = self.robot.joints[name].mimic
            if m is not None and m.joint in movable:
                poly = [m.offset or 0.0, 1.0 if m.multiplier is None else m.multiplier, 0.0, 0.0, 0.0]
                self.leaf(depth, "joint", [("joint1", name), ("joint2", m.joint),
                                           ("polycoef", fmt_floats(poly))])
        for c in self._written_cuts():  # site1 on the parent, site2 on the child
            for suffix, _, _ in cut_sites(c):
                # `<cut>_axis` unless another cut joint has that name (then unnamed)
                name = c.name + suffix if not suffix or c.name + suffix not in self.robot.cut_joints else None
                self.leaf(depth, "weld" if c.type == "fixed" else "connect", [
                    ("name", name), ("site1", f"{c.name}_parent{suffix}"),
                    ("site2", f"{c.name}_child{suffix}")])

    def _emit_actuators(self, depth: int = 2) -> None:
        for a in mjcf_actuation.actuators(self.robot, self.actuator_mode):
            pairs: Pairs = [(k, v if v is None or isinstance(v, str) else
                             fmt_floats(v) if isinstance(v, tuple) else fmt_float(v)) for k, v in a.attrs]
            self.leaf(depth, a.tag, [("name", a.name), ("joint", a.joint), *pairs])

    def _emit_contacts(self, depth: int = 2) -> None:
        for a, b in mjcf_contacts.excluded_pairs(self.robot):
            self.leaf(depth, "exclude", [("body1", a), ("body2", b)])

    def _emit_keyframes(self, depth: int = 2) -> None:
        """A key per named pose: the pose's joint values, q0 elsewhere (a mimic follower where its
        leader puts it); ctrl holds a position actuator at its joint's value, the others at 0."""
        acts = mjcf_actuation.actuators(self.robot, self.actuator_mode)
        for name, values in self.robot.poses.items():
            q = {j: float(v) for j, v in values.items() if _one_dof(self.robot.joints.get(j))}
            for j in [n for n in self.robot.joints if n not in q]:
                m = self.robot.joints[j].mimic
                if m is not None and _one_dof(self.robot.joints[j]) and m.joint in q:
                    q[j] = (m.offset or 0.0) + (1.0 if m.multiplier is None else m.multiplier) * q[m.joint]
            qpos = [q.get(j, x) if j is not None else x for j, x in self.qpos]
            ctrl = [q.get(a.joint, 0.0) if a.tag == "position" else 0.0 for a in acts]
            self.leaf(depth, "key", [("name", name), ("qpos", fmt_floats(qpos) if qpos else None),
                                     ("ctrl", fmt_floats(ctrl) if ctrl else None)])

    def document(self) -> str:
        """Worldbody first: it names the mesh assets, which come before it in the file."""
        parts = []
        for emit_part in (self._emit_worldbody, self._emit_contacts, self._emit_equality,
                          self._emit_actuators, self._emit_keyframes):
            self.out = []
            emit_part()
            parts.append(self.out)
        body, contact, equality, actuator, keyframe = parts
        self.out = [f'<mujoco{_attrs([("model", self.robot.name)])}>']
        self.leaf(1, "compiler", COMPILER)
        self.out.append(f'{IND}<option integrator="implicitfast">')
        self.leaf(2, "flag", [("filterparent", "disable")])
        self.out.append(f"{IND}</option>")
        assets = [(name, file, scale) for (file, scale), name in self.assets.items()]
        self.out += [f"{IND}<asset>"] * bool(assets or self.materials)
        for (_, rgba), name in self.materials.items():
            self.leaf(2, "material", [("name", name), ("rgba", rgba)])
        for name, file, scale in assets:
            self.leaf(2, "mesh", [("name", name), ("file", file), ("scale", scale), ("inertia", "shell")])
        self.out += [f"{IND}</asset>"] * bool(assets or self.materials) + body
        for tag, lines in (("contact", contact), ("equality", equality), ("actuator", actuator),
                           ("keyframe", keyframe)):
            self.out += [f"{IND}<{tag}>", *lines, f"{IND}</{tag}>"] if lines else []
        return "\n".join([*self.out, "</mujoco>"]) + "\n"


def _zeroed(text: str | None) -> str | None:
    """`text` (numbers) with those closer to zero than 1e-12 written as 0 (`enforce_zero`)."""
    if text is None:
        return None
    return " ".join("0" if abs(float(t)) < EPSILON else t for t in text.split())


def to_string(robot: Robot, mesh_name: Callable[[Mesh], str], sink: Sink | None = None,
              formats: Formats | None = None, enforce_zero: bool = False, actuators: str = "motors") -> str:
    """The canonical MJCF text of `robot`; `mesh_name` gives each mesh's file relative to it;
    `formats`: the number formats of `float_fmt_dict`, when given; `actuators`: the export's
    option (backends/mjcf_actuation.py). With a sink, also reports what MuJoCo would refuse
    (E0504) and what is left out (W0500)."""
    if sink is not None:
        _diagnose(robot, sink, robot.span or Span.of_file(robot.name), actuators)
    return _Writer(robot, mesh_name, formats, enforce_zero, actuators).document()


def body_depth(robot: Robot) -> tuple[int, str]:
    """How deep the MJCF's bodies nest (the world's children are 1), and the deepest link:
    the root is a body unless it is `world`; a floating joint's body is hoisted to the world."""
    hoisted = robot.root != "world"
    depth: dict[str, int] = {robot.root: 0 if robot.root == "world" else 1}
    deepest = robot.root
    for joint, link in depth_first(robot):
        if joint is None:
            continue
        top = hoisted and joint.parent == robot.root and joint.type == "floating"
        depth[link] = 1 if top else depth[joint.parent] + 1
        if depth[link] > depth[deepest]:
            deepest = link
    return depth[deepest], deepest


def _diagnose(robot: Robot, sink: Sink, span: Span, actuators: str = "motors") -> bool:
    """Report what MuJoCo refuses (E0504, E0695) and what is left out (W0500); whether the
    MJCF can be written (E0695: MuJoCo could not even parse it)."""
    depth, deepest = body_depth(robot)
    if depth > MAX_BODY_DEPTH:
        sink.error(span, "E0695", f"the MJCF cannot hold this robot: its bodies would nest {depth} "
                   f"deep (down to link '{deepest}'), and MuJoCo's XML reader refuses elements nested "
                   f"deeper than {MAX_BODY_DEPTH} bodies; no MJCF is written",
                   hint="export this model as URDF or SDF, or cut it into submodels")
        return False
    unusable = [(link, problem) for link, body in robot.links.items() if body.inertial is not None
                and (problem := unusable_inertial(body.inertial)) is not None]
    for link, problem in unusable:
        sink.error(robot.links[link].span or span, "E0586", f"link '{link}' has an inertial MuJoCo "
                   f"cannot hold: {problem}; no MJCF is written", hint="fix its <inertial>")
    if unusable:
        return False
    check(robot, sink, span)
    missing = left_out(robot, actuators)
    if missing:
        sink.warning(span, "W0500", "the MJCF leaves out what it cannot hold: " + ", ".join(missing))
    return True


def emit(robot: Robot, export: MjcfExport, out: Path, sink: Sink) -> None:
    """Write `out/mjcf/<filename or robot.name>.xml`, meshes under `out/meshes/<stl|obj>/`."""
    if export.mesh_format not in ("stl", "obj"):
        sink.error(export.span, "E0501", f"MuJoCo reads no '{export.mesh_format}' meshes",
                   hint="use mesh_format stl or obj for an mjcf export")
        return
    if not _diagnose(robot, sink, export.span, export.actuators):
        return
    prepared = meshes.for_export(coloured(robot), export, out, sink, mujoco=True)
    if prepared is None:
        return
    robot, files = prepared
    formats = Formats(export.float_formats, MJCF_KEYS) if export.float_formats else None
    text = to_string(robot, meshes.namer(files, "../"), formats=formats, enforce_zero=export.enforce_zero,
                     actuators=export.actuators)
    name = export.filename or robot.name
    path = confined(out, "mjcf", f"{name}.xml")
    write_path(path, text)
    if export.scene:
        said: list[str] = []
        try:
            floor = mjcf_scene.floor_height(path, COLLISION_GROUP, said)
        except ValueError as e:
            sink.error(export.span, "E0696", f"MuJoCo refuses the MJCF of robot '{robot.name}', so its "
                       f"scene cannot place the floor: {e}")
            return
        for message in dict.fromkeys(said):
            sink.warning(export.span, "W0506", f"MuJoCo warns about the MJCF of robot '{robot.name}' "
                         f"as it loads it to place the scene's floor: {message}")
        write_path(confined(out, "mjcf", f"{name}_scene.xml"), mjcf_scene.scene(robot, f"{name}.xml", floor))
