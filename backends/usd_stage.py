"""ir.Robot → an OpenUSD stage with UsdGeom, UsdShade and UsdPhysics (usd-core), in three
parts: geometry (links as Xforms, visuals and collisions as meshes and primitives), materials
(UsdPreviewSurface, bound to the visuals) and physics (rigid bodies, mass, collision APIs,
joints, drives, mimic, filtered pairs). Each part is authored into its own layer (the
default layout) or all into one (`layout: single`); backends/usd.py writes them.

Prims: `/<robot>` (the default prim, an articulation root), one Xform per link directly below
it at the link's pose in the root frame at q = 0 (translate and orient, doubles), with
`visuals/` and `collisions/` below; `/<robot>/joints/<joint>`; `/<robot>/materials/<material>`.
Every prim name is a valid identifier (backends/usd_names.py), the original name is `mpc:name`.

Joints (UsdPhysics stores floats): body0 = the parent link, localPos0/localRot0 = the joint
frame in it; body1 = the child link, localPos1 = 0. UsdPhysics names an axis X, Y or Z of the
joint frame: the frame is turned by R_a, which takes that unit vector (the axis's largest
component) to the joint's axis, so localRot0 = R_PJ·R_a and localRot1 = R_a. Revolute limits
in degrees, prismatic in metres; continuous: no limits. A motor is a DriveAPI (angular or
linear, type force): stiffness p and damping d of its settings, per degree for an angular
drive, maxForce the joint's effort limit. Mimic joints carry NewtonMimicAPI (Newton's schema:
joint0 = coef0 + coef1·joint1, coef0 in degrees for a revolute joint); velocity limits,
damping and friction NewtonJointAPI (`newton:velocityLimit`, `newton:damping`,
`newton:friction`, per degree on a rotational joint), as NVIDIA's converter writes them. Loop closures
(cut joints) are joints excluded from the articulation: fixed, spherical (ball) and revolute
(with an axis); W0500 names the others.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from mpc.backends import usd_specs as specs
from mpc.backends.mjcf import cut_sites, principal
from mpc.backends.usd_kinds import ONE_DOF, closed_cut_axis, mimic_written, written_cut
from mpc.backends.usd_meshes import Triangles
from mpc.backends.usd_names import sibling_names, unique_identifiers
from mpc.backends.usd_pxr import Gf, Layer, PrimPath, Quat, Sdf, Vt
from mpc.backends.usd_specs import PrimSpec, T
from mpc.core.record import record
from mpc.ir import transforms as tf
from mpc.ir.extras import CutJoint
from mpc.ir.geometry import Box, ConvexHull, ConvexPart, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.kinematics import links_in_root, pose_matrix
from mpc.ir.robot import Collision, Joint, Link, Material, Robot, Visual
from mpc.ir.tree import depth_first

NAME = "mpc:name"  # the original name of a prim's element
_AXES = ("X", "Y", "Z")
DEG = 180.0 / math.pi


@record
class Layers:
    """Where each part is authored (the same layer for `layout: single`)."""

    geometry: Layer
    materials: Layer
    physics: Layer


def quatd(R: np.ndarray) -> Quat:
    w, x, y, z = tf.matrix_to_quat(R)
    return Gf.Quatd(w, Gf.Vec3d(x, y, z))


def quatf(R: np.ndarray) -> Quat:
    w, x, y, z = tf.matrix_to_quat(R)
    return Gf.Quatf(w, Gf.Vec3f(x, y, z))


def axis_frame(axis: tuple[float, float, float] | None) -> tuple[str, np.ndarray]:
    """The UsdPhysics axis token for a joint axis, and R_a, the rotation that takes that unit
    vector to the axis (the identity when the axis is one)."""
    a = np.asarray(axis if axis is not None else (1.0, 0.0, 0.0), dtype=float)
    a *= 1 / np.linalg.norm(a)
    k = int(np.argmax(np.abs(a)))
    e = np.eye(3)[k]
    if np.array_equal(a, e):
        return _AXES[k], np.eye(3)
    v, c = np.cross(e, a), float(e @ a)
    if c < -1 + 1e-12:  # opposite: half a turn about another unit axis
        u = np.eye(3)[(k + 1) % 3]
        return _AXES[k], 2 * np.outer(u, u) - np.eye(3)
    V = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return _AXES[k], np.eye(3) + V + (V @ V) * (1 / (1 + c))


def _material_of(robot: Robot, visual: Visual) -> Material | None:
    return visual.inline_material or robot.materials.get(visual.material or "")


def approximation(mesh: Mesh) -> str:
    """MeshCollisionAPI's approximation of a collision mesh: its hull or a part of its convex
    decomposition (both convex, computed by mpc) is `convexHull`; another mesh is `none`."""
    return "convexHull" if any(isinstance(op, ConvexHull | ConvexPart) for op in mesh.ops) else "none"


class Author:
    """Authors one robot into its layers (see the module's docstring), as specs
    (backends/usd_specs.py)."""

    def __init__(self, robot: Robot, layers: Layers, triangles: Callable[[Mesh], Triangles]) -> None:
        self.robot, self.layers, self.triangles = robot, layers, triangles
        self.root = Sdf.Path("/" + unique_identifiers([robot.name])[robot.name])
        self.order = [link for _, link in depth_first(robot)]
        self.link_names = unique_identifiers(self.order, taken=("joints", "materials"))
        self.X = links_in_root(robot)
        self.joint_names: dict[str, str] = {}
        self.arrays: dict[int, tuple[Any, Any, Any, Any]] = {}

    def shape_paths(self, link: Link, kind: str) -> list[PrimPath]:
        """The prims of a link's visuals or collisions (`kind`), in their order."""
        shapes = link.visuals if kind == "visuals" else link.collisions
        folder = self.link_path(link.name).AppendChild(kind)
        return [folder.AppendChild(n) for n in sibling_names(s.name or kind[:-1] for s in shapes)]

    def link_path(self, link: str) -> PrimPath:
        return self.root.AppendChild(self.link_names[link])

    # geometry ------------------------------------------------------------------------------

    def geometry(self) -> None:
        layer = self.layers.geometry
        top = specs.prim(layer, self.root, "Xform")
        top.kind = "component"
        _name(top, self.robot.name)
        for link in self.order:
            xform = specs.prim(layer, self.link_path(link), "Xform")
            _name(xform, link)
            _place(xform, self.X[link][:3, 3], self.X[link][:3, :3])
            lk = self.robot.links[link]
            for kind, shapes in (("visuals", lk.visuals), ("collisions", lk.collisions)):
                if not shapes:
                    continue
                specs.prim(layer, self.link_path(link).AppendChild(kind), "Scope")
                for path, shape in zip(self.shape_paths(lk, kind), shapes, strict=True):
                    self.shape(path, shape)

    def mesh_arrays(self, mesh: Mesh) -> tuple[Any, Any, Any, Any]:
        """A mesh's points, face sizes, indices and extent as USD's arrays, made once for each
        mesh file and ops (a leg's mesh used four times is converted once)."""
        points, faces, (lo, hi) = self.triangles(mesh)
        key = id(points)
        if key not in self.arrays:
            self.arrays[key] = (Vt.Vec3fArray.FromNumpy(points),
                                Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)),
                                Vt.IntArray.FromNumpy(faces.reshape(-1)),
                                Vt.Vec3fArray([Gf.Vec3f(*lo), Gf.Vec3f(*hi)]) if lo else Vt.Vec3fArray())
        return self.arrays[key]

    def shape(self, path: PrimPath, shape: Visual | Collision) -> None:
        g: Geometry = shape.geometry
        scale: tuple[float, ...] | None = None
        layer = self.layers.geometry
        match g:
            case Box():
                spec = specs.prim(layer, path, "Cube")
                specs.attribute(spec, "size", T.Double, 1.0)
                scale = g.size
            case Sphere():
                spec = specs.prim(layer, path, "Sphere")
                specs.attribute(spec, "radius", T.Double, g.radius)
            case Cylinder():
                spec = specs.prim(layer, path, "Cylinder")
                specs.attribute(spec, "radius", T.Double, g.radius)
                specs.attribute(spec, "height", T.Double, g.length)
                specs.attribute(spec, "axis", T.Token, "Z", uniform=True)
            case Mesh():
                spec = specs.prim(layer, path, "Mesh")
                points, counts, indices, extent = self.mesh_arrays(g)
                specs.attribute(spec, "points", T.Point3fArray, points)
                specs.attribute(spec, "faceVertexCounts", T.IntArray, counts)
                specs.attribute(spec, "faceVertexIndices", T.IntArray, indices)
                specs.attribute(spec, "subdivisionScheme", T.Token, "none", uniform=True)
                specs.attribute(spec, "extent", T.Float3Array, extent)
                scale = g.scale
            case _:
                raise AssertionError(f"no USD prim for {g!r}")
        X = pose_matrix(shape.origin)
        _place(spec, X[:3, 3], X[:3, :3], scale)
        _name(spec, shape.name or "")
        if isinstance(shape, Collision):
            specs.attribute(spec, "purpose", T.Token, "guide", uniform=True)
            return
        m = _material_of(self.robot, shape)
        if m is not None and m.rgba is not None:
            specs.attribute(spec, "primvars:displayColor", T.Color3fArray,
                            Vt.Vec3fArray([Gf.Vec3f(*m.rgba[:3])]))
            if m.rgba[3] != 1:
                specs.attribute(spec, "primvars:displayOpacity", T.FloatArray, Vt.FloatArray([m.rgba[3]]))

    # materials -----------------------------------------------------------------------------

    def materials_part(self) -> None:
        """One UsdPreviewSurface material per distinct coloured material (name, colour and
        emission), bound to its visuals."""
        layer = self.layers.materials
        used: dict[tuple[object, ...], Material] = {}
        for link in self.order:
            for visual in self.robot.links[link].visuals:
                m = _material_of(self.robot, visual)
                if m is not None and m.rgba is not None:
                    used.setdefault(_material_key(m), m)
        if not used:
            return
        folder = self.root.AppendChild("materials")
        specs.prim(layer, folder, "Scope")
        paths: dict[tuple[object, ...], PrimPath] = {}
        for (key, m), name in zip(used.items(), sibling_names(m.name for m in used.values()), strict=True):
            paths[key] = path = folder.AppendChild(name)
            material = specs.prim(layer, path, "Material")
            _name(material, m.name)
            shader_path = path.AppendChild("PreviewSurface")
            shader = specs.prim(layer, shader_path, "Shader")
            specs.attribute(shader, "info:id", T.Token, "UsdPreviewSurface", uniform=True)
            assert m.rgba is not None
            specs.attribute(shader, "inputs:diffuseColor", T.Color3f, Gf.Vec3f(*m.rgba[:3]))
            specs.attribute(shader, "inputs:opacity", T.Float, float(m.rgba[3]))
            if m.emissive is not None and len(m.emissive) >= 3:
                specs.attribute(shader, "inputs:emissiveColor", T.Color3f,
                                Gf.Vec3f(*(float(c) for c in m.emissive[:3])))
            Sdf.AttributeSpec(shader, "outputs:surface", T.Token)
            specs.connect(material, "outputs:surface", T.Token, shader_path.AppendProperty("outputs:surface"))
        for link in self.order:
            lk = self.robot.links[link]
            for path, visual in zip(self.shape_paths(lk, "visuals"), lk.visuals, strict=True):
                m = _material_of(self.robot, visual)
                if m is None or m.rgba is None:
                    continue
                spec = specs.prim(layer, path)
                specs.apply(spec, "MaterialBindingAPI")
                specs.relationship(spec, "material:binding", [paths[_material_key(m)]])

    # physics -------------------------------------------------------------------------------

    def physics(self) -> None:
        layer = self.layers.physics
        specs.apply(specs.prim(layer, self.root), "PhysicsArticulationRootAPI")
        static = self.static_root()
        for link in self.order:
            if link != static:
                self.body(specs.prim(layer, self.link_path(link)), link)
            lk = self.robot.links[link]
            for path, c in zip(self.shape_paths(lk, "collisions"), lk.collisions, strict=True):
                cspec = specs.prim(layer, path)
                specs.apply(cspec, "PhysicsCollisionAPI")
                if isinstance(c.geometry, Mesh):
                    specs.apply(cspec, "PhysicsMeshCollisionAPI")
                    specs.attribute(cspec, "physics:approximation", T.Token, approximation(c.geometry),
                                    uniform=True)
        self.filtered_pairs()
        folder = self.root.AppendChild("joints")
        joints = [j for j, _ in depth_first(self.robot) if j is not None]
        cuts = [self.robot.cut_joints[n] for n in sorted(self.robot.cut_joints)]
        written = [j for j in joints if j.type not in ("floating", "planar")]
        closed = [c for c in cuts if written_cut(c)]
        if not written and not closed:
            return
        specs.prim(layer, folder, "Scope")
        self.joint_names = unique_identifiers([*(j.name for j in written), *(c.name for c in closed)])
        for j in written:
            self.joint(folder.AppendChild(self.joint_names[j.name]), j)
        for j in written:
            self.mimic(folder, j)
        for c in closed:
            self.cut(folder.AppendChild(self.joint_names[c.name]), c)

    def static_root(self) -> str | None:
        """The root link `world` without mass is the world, not a body (URDF's convention)."""
        root = self.robot.links[self.robot.root]
        massless = root.inertial is None or root.inertial.mass == 0
        return root.name if root.name == "world" and massless else None

    def body(self, spec: PrimSpec, link: str) -> None:
        """RigidBodyAPI and MassAPI: mass, centre of mass, and the principal moments and axes
        (mjcf.principal). A link without inertial, or with a zero tensor, gets mass and centre
        of mass only: UsdPhysics reads a zero diagonal inertia as "not given", and its
        validator refuses one authored."""
        specs.apply(spec, "PhysicsRigidBodyAPI", "PhysicsMassAPI")
        inertial = self.robot.links[link].inertial
        specs.attribute(spec, "physics:mass", T.Float, float(inertial.mass) if inertial is not None else 0.0)
        if inertial is None:
            return
        xyz = inertial.origin.xyz if inertial.origin is not None else (0.0, 0.0, 0.0)
        specs.attribute(spec, "physics:centerOfMass", T.Point3f, Gf.Vec3f(*xyz))
        d, q = principal(inertial)
        if any(d):
            specs.attribute(spec, "physics:diagonalInertia", T.Float3, Gf.Vec3f(*d))
            specs.attribute(spec, "physics:principalAxes", T.Quatf,
                            Gf.Quatf(q[0], Gf.Vec3f(q[1], q[2], q[3])))

    def filtered_pairs(self) -> None:
        """Links none of whose collisions share a bitmask bit with the other's never collide:
        FilteredPairsAPI on the first of the two (in depth-first order), naming the other.
        Only when some collision has a bitmask (without one, a collision collides with all)."""
        shapes = {link: [c.bitmask for c in self.robot.links[link].collisions] for link in self.order}
        if not any(b is not None for masks in shapes.values() for b in masks):
            return
        colliding = [link for link in self.order if shapes[link]]
        for i, a in enumerate(colliding):
            others = [b for b in colliding[i + 1:] if all(
                x is not None and y is not None and not (x & y) for x in shapes[a] for y in shapes[b])]
            if others:
                spec = specs.prim(self.layers.physics, self.link_path(a))
                specs.apply(spec, "PhysicsFilteredPairsAPI")
                specs.relationship(spec, "physics:filteredPairs", [self.link_path(b) for b in others])

    def _frame(self, joint: PrimSpec, parent: str, child: str, X_PJ: np.ndarray, X_CJ: np.ndarray,
               R_a: np.ndarray) -> None:
        specs.relationship(joint, "physics:body0", [self.link_path(parent)])
        specs.relationship(joint, "physics:body1", [self.link_path(child)])
        specs.attribute(joint, "physics:localPos0", T.Point3f, Gf.Vec3f(*map(float, X_PJ[:3, 3])))
        specs.attribute(joint, "physics:localRot0", T.Quatf, quatf(X_PJ[:3, :3] @ R_a))
        specs.attribute(joint, "physics:localPos1", T.Point3f, Gf.Vec3f(*map(float, X_CJ[:3, 3])))
        specs.attribute(joint, "physics:localRot1", T.Quatf, quatf(X_CJ[:3, :3] @ R_a))

    def _limits(self, joint: PrimSpec, lower: float, upper: float) -> None:
        specs.attribute(joint, "physics:lowerLimit", T.Float, lower)
        specs.attribute(joint, "physics:upperLimit", T.Float, upper)

    def joint(self, path: PrimPath, j: Joint) -> None:
        token, R_a = axis_frame(j.axis) if j.type in ONE_DOF else ("X", np.eye(3))
        layer = self.layers.physics
        lim = j.limit
        limited = lim is not None and (lim.lower is not None or lim.upper is not None)
        if j.type in ("revolute", "continuous"):
            spec = specs.prim(layer, path, "PhysicsRevoluteJoint")
            specs.attribute(spec, "physics:axis", T.Token, token, uniform=True)
            if j.type == "revolute" and lim is not None and limited:
                self._limits(spec, (lim.lower or 0.0) * DEG, (lim.upper or 0.0) * DEG)
        elif j.type == "prismatic":
            spec = specs.prim(layer, path, "PhysicsPrismaticJoint")
            specs.attribute(spec, "physics:axis", T.Token, token, uniform=True)
            if lim is not None and limited:
                self._limits(spec, lim.lower or 0.0, lim.upper or 0.0)
        else:
            spec = specs.prim(layer, path, "PhysicsFixedJoint")
        _name(spec, j.name)
        self._frame(spec, j.parent, j.child, pose_matrix(j.origin), np.eye(4), R_a)
        self.drive(spec, j)
        self.dynamics(spec, j)

    def dynamics(self, spec: PrimSpec, j: Joint) -> None:
        """The joint's velocity limit, damping and friction as NewtonJointAPI holds them (per
        degree on a rotational joint); UsdPhysics has none."""
        if j.type not in ONE_DOF:
            return
        angular = j.type != "prismatic"
        values = [("newton:velocityLimit", j.limit.velocity if j.limit is not None else None,
                   DEG if angular else 1.0),
                  ("newton:damping", j.dynamics.damping if j.dynamics is not None else None,
                   1 / DEG if angular else 1.0),
                  ("newton:friction", j.dynamics.friction if j.dynamics is not None else None, 1.0)]
        given = [(name, float(value) * unit) for name, value, unit in values if value is not None]
        if not given:
            return
        specs.apply(spec, "NewtonJointAPI")
        for name, value in given:
            specs.attribute(spec, name, T.Float, value)

    def drive(self, spec: PrimSpec, j: Joint) -> None:
        """The motor of a one-degree-of-freedom joint as a DriveAPI (see the module)."""
        motors = [m for m in (self.robot.motors[n] for n in sorted(self.robot.motors)) if m.joint == j.name]
        if not motors or j.type not in ONE_DOF:
            return
        settings = motors[0].settings
        angular = j.type != "prismatic"
        per = math.pi / 180 if angular else 1.0  # N·m/rad → N·m/degree
        kind = "angular" if angular else "linear"
        specs.apply(spec, f"PhysicsDriveAPI:{kind}")
        specs.attribute(spec, f"drive:{kind}:physics:type", T.Token, "force", uniform=True)
        for key, attr in (("p", "stiffness"), ("d", "damping")):
            value = settings.get(key)
            if isinstance(value, int | float) and not isinstance(value, bool):
                specs.attribute(spec, f"drive:{kind}:physics:{attr}", T.Float, float(value) * per)
        effort = j.limit.effort if j.limit is not None else None
        if effort:
            specs.attribute(spec, f"drive:{kind}:physics:maxForce", T.Float, abs(effort))

    def mimic(self, folder: PrimPath, j: Joint) -> None:
        """NewtonMimicAPI on a one-degree-of-freedom joint that follows another of the same kind."""
        m = j.mimic
        leader = self.robot.joints.get(m.joint) if m is not None else None
        if m is None or not mimic_written(j, leader):
            return
        spec = specs.prim(self.layers.physics, folder.AppendChild(self.joint_names[j.name]))
        specs.apply(spec, "NewtonMimicAPI")
        specs.relationship(spec, "newton:mimicJoint", [folder.AppendChild(self.joint_names[m.joint])])
        offset = (m.offset or 0.0) * (DEG if j.type != "prismatic" else 1.0)
        specs.attribute(spec, "newton:mimicCoef0", T.Float, offset)
        specs.attribute(spec, "newton:mimicCoef1", T.Float, 1.0 if m.multiplier is None else m.multiplier)

    def cut(self, path: PrimPath, c: CutJoint) -> None:
        """A loop closure: a joint excluded from the articulation, at the closure's frame on
        both sides (mjcf.cut_sites)."""
        _, on_parent, on_child = cut_sites(c)[0]
        R_a = np.eye(3)
        layer = self.layers.physics
        if c.type == "fixed":
            spec = specs.prim(layer, path, "PhysicsFixedJoint")
        elif c.type == "ball":
            spec = specs.prim(layer, path, "PhysicsSphericalJoint")
        else:
            axis = closed_cut_axis(c)
            assert axis is not None
            # the axis is in the child link's frame; the joint frame's own axis is R_CJᵀ·a
            R_CJ = pose_matrix(on_child)[:3, :3]
            token, R_a = axis_frame(tuple(float(x) for x in R_CJ.T @ np.asarray(axis)))  # type: ignore[arg-type]
            spec = specs.prim(layer, path, "PhysicsRevoluteJoint")
            specs.attribute(spec, "physics:axis", T.Token, token, uniform=True)
        specs.attribute(spec, "physics:excludeFromArticulation", T.Bool, True, uniform=True)
        _name(spec, c.name)
        self._frame(spec, c.parent, c.child, pose_matrix(on_parent), pose_matrix(on_child), R_a)


def _material_key(m: Material) -> tuple[object, ...]:
    return (m.name, m.rgba, m.emissive)


def _name(spec: PrimSpec, name: str) -> None:
    specs.attribute(spec, NAME, T.String, name, custom=True)


def _place(spec: PrimSpec, xyz: np.ndarray | tuple[float, ...], R: np.ndarray,
           scale: tuple[float, ...] | None = None) -> None:
    """translate and orient (doubles), and scale when given; only those not the identity."""
    identity = R[0, 0] == R[1, 1] == R[2, 2] == 1 and not (R[0, 1] or R[0, 2] or R[1, 0] or R[1, 2]
                                                           or R[2, 0] or R[2, 1])
    specs.place(spec,
                translate=Gf.Vec3d(*map(float, xyz)) if any(float(x) != 0 for x in xyz) else None,
                orient=None if identity else quatd(R),
                scale=Gf.Vec3d(*map(float, scale)) if scale is not None and tuple(scale) != (1.0, 1.0, 1.0)
                else None)
