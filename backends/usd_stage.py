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
from dataclasses import dataclass
from typing import Any

import numpy as np

from mpc.backends.mjcf import cut_sites, principal
from mpc.backends.usd_kinds import ONE_DOF, closed_cut_axis, mimic_written, written_cut
from mpc.backends.usd_meshes import Triangles
from mpc.backends.usd_names import sibling_names, unique_identifiers
from mpc.backends.usd_pxr import (
    Gf,
    Layer,
    PhysicsJoint,
    Prim,
    PrimPath,
    Quat,
    Sdf,
    Stage,
    Usd,
    UsdGeom,
    UsdPhysics,
    UsdShade,
    Vt,
    Xformable,
)
from mpc.ir import transforms as tf
from mpc.ir.extras import CutJoint
from mpc.ir.geometry import Box, ConvexHull, ConvexPart, Cylinder, Geometry, Mesh, Sphere
from mpc.ir.kinematics import links_in_root, pose_matrix
from mpc.ir.robot import Collision, Joint, Link, Material, Robot, Visual
from mpc.ir.tree import depth_first

NAME = "mpc:name"  # the original name of a prim's element
_AXES = ("X", "Y", "Z")
DEG = 180.0 / math.pi


@dataclass(frozen=True)
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
    """Authors one robot onto a stage (see the module's docstring)."""

    def __init__(self, robot: Robot, stage: Stage, layers: Layers,
                 triangles: Callable[[Mesh], Triangles]) -> None:
        self.robot, self.stage, self.layers, self.triangles = robot, stage, layers, triangles
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

    def target(self, layer: Layer) -> None:
        self.stage.SetEditTarget(Usd.EditTarget(layer))

    def link_path(self, link: str) -> PrimPath:
        return self.root.AppendChild(self.link_names[link])

    # geometry ------------------------------------------------------------------------------

    def geometry(self) -> None:
        self.target(self.layers.geometry)
        top = UsdGeom.Xform.Define(self.stage, self.root)
        Usd.ModelAPI(top.GetPrim()).SetKind("component")
        _name(top.GetPrim(), self.robot.name)
        for link in self.order:
            xform = UsdGeom.Xform.Define(self.stage, self.link_path(link))
            _name(xform.GetPrim(), link)
            _place(xform, self.X[link][:3, 3], self.X[link][:3, :3])
            lk = self.robot.links[link]
            for kind, shapes in (("visuals", lk.visuals), ("collisions", lk.collisions)):
                if not shapes:
                    continue
                UsdGeom.Scope.Define(self.stage, self.link_path(link).AppendChild(kind))
                for path, shape in zip(self.shape_paths(lk, kind), shapes, strict=True):
                    prim = self.shape(path, shape)
                    if isinstance(shape, Collision):
                        UsdGeom.Imageable(prim).CreatePurposeAttr(UsdGeom.Tokens.guide)

    def mesh_arrays(self, mesh: Mesh) -> tuple[Any, Any, Any, Any]:
        """A mesh's points, face sizes, indices and extent as USD's arrays, made once for each
        mesh file and ops (a leg's mesh used four times is converted once)."""
        points, faces = self.triangles(mesh)
        key = id(points)
        if key not in self.arrays:
            lo, hi = points.min(axis=0), points.max(axis=0)
            self.arrays[key] = (Vt.Vec3fArray.FromNumpy(points),
                                Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)),
                                Vt.IntArray.FromNumpy(faces.reshape(-1)),
                                Vt.Vec3fArray([Gf.Vec3f(*map(float, lo)), Gf.Vec3f(*map(float, hi))]))
        return self.arrays[key]

    def shape(self, path: PrimPath, shape: Visual | Collision) -> Prim:
        g: Geometry = shape.geometry
        scale: tuple[float, ...] | None = None
        match g:
            case Box():
                prim = UsdGeom.Cube.Define(self.stage, path)
                prim.CreateSizeAttr(1.0)
                scale = g.size
            case Sphere():
                prim = UsdGeom.Sphere.Define(self.stage, path)
                prim.CreateRadiusAttr(g.radius)
            case Cylinder():
                prim = UsdGeom.Cylinder.Define(self.stage, path)
                prim.CreateRadiusAttr(g.radius)
                prim.CreateHeightAttr(g.length)
                prim.CreateAxisAttr(UsdGeom.Tokens.z)
            case Mesh():
                prim = UsdGeom.Mesh.Define(self.stage, path)
                points, counts, indices, extent = self.mesh_arrays(g)
                prim.CreatePointsAttr(points)
                prim.CreateFaceVertexCountsAttr(counts)
                prim.CreateFaceVertexIndicesAttr(indices)
                prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
                prim.CreateExtentAttr(extent)
                scale = g.scale
        X = pose_matrix(shape.origin)
        _place(prim, X[:3, 3], X[:3, :3], scale)
        _name(prim.GetPrim(), shape.name or "")
        if isinstance(shape, Visual):
            m = _material_of(self.robot, shape)
            if m is not None and m.rgba is not None:
                prim.CreateDisplayColorAttr(Vt.Vec3fArray([Gf.Vec3f(*m.rgba[:3])]))
                if m.rgba[3] != 1:
                    prim.CreateDisplayOpacityAttr(Vt.FloatArray([m.rgba[3]]))
        return prim.GetPrim()

    # materials -----------------------------------------------------------------------------

    def materials_part(self) -> None:
        """One UsdPreviewSurface material per distinct coloured material (name, colour and
        emission), bound to its visuals."""
        self.target(self.layers.materials)
        used: dict[tuple[object, ...], Material] = {}
        for link in self.order:
            for visual in self.robot.links[link].visuals:
                m = _material_of(self.robot, visual)
                if m is not None and m.rgba is not None:
                    used.setdefault(_material_key(m), m)
        if not used:
            return
        folder = self.root.AppendChild("materials")
        UsdGeom.Scope.Define(self.stage, folder)
        paths: dict[tuple[object, ...], PrimPath] = {}
        for (key, m), name in zip(used.items(), sibling_names(m.name for m in used.values()), strict=True):
            paths[key] = path = folder.AppendChild(name)
            material = UsdShade.Material.Define(self.stage, path)
            _name(material.GetPrim(), m.name)
            shader = UsdShade.Shader.Define(self.stage, path.AppendChild("PreviewSurface"))
            shader.CreateIdAttr("UsdPreviewSurface")
            assert m.rgba is not None
            shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*m.rgba[:3]))
            shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(float(m.rgba[3]))
            if m.emissive is not None and len(m.emissive) >= 3:
                shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(
                    Gf.Vec3f(*(float(c) for c in m.emissive[:3])))
            material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        for link in self.order:
            lk = self.robot.links[link]
            for path, visual in zip(self.shape_paths(lk, "visuals"), lk.visuals, strict=True):
                m = _material_of(self.robot, visual)
                if m is None or m.rgba is None:
                    continue
                UsdShade.MaterialBindingAPI.Apply(self.stage.OverridePrim(path)).Bind(
                    UsdShade.Material(self.stage.GetPrimAtPath(paths[_material_key(m)])))

    # physics -------------------------------------------------------------------------------

    def physics(self) -> None:
        self.target(self.layers.physics)
        UsdPhysics.ArticulationRootAPI.Apply(self.stage.OverridePrim(self.root))
        static = self.static_root()
        for link in self.order:
            prim = self.stage.OverridePrim(self.link_path(link))
            if link != static:
                self.body(prim, link)
            lk = self.robot.links[link]
            for path, c in zip(self.shape_paths(lk, "collisions"), lk.collisions, strict=True):
                cprim = self.stage.OverridePrim(path)
                UsdPhysics.CollisionAPI.Apply(cprim)
                if isinstance(c.geometry, Mesh):
                    UsdPhysics.MeshCollisionAPI.Apply(cprim).CreateApproximationAttr(approximation(c.geometry))
        self.filtered_pairs()
        folder = self.root.AppendChild("joints")
        joints = [j for j, _ in depth_first(self.robot) if j is not None]
        cuts = [self.robot.cut_joints[n] for n in sorted(self.robot.cut_joints)]
        written = [j for j in joints if j.type not in ("floating", "planar")]
        closed = [c for c in cuts if written_cut(c)]
        if not written and not closed:
            return
        self.stage.DefinePrim(folder, "Scope")
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

    def body(self, prim: Prim, link: str) -> None:
        """RigidBodyAPI and MassAPI: mass, centre of mass, and the principal moments and axes
        (mjcf.principal). A link without inertial, or with a zero tensor, gets mass and centre
        of mass only: UsdPhysics reads a zero diagonal inertia as "not given", and its
        validator refuses one authored."""
        UsdPhysics.RigidBodyAPI.Apply(prim)
        mass = UsdPhysics.MassAPI.Apply(prim)
        inertial = self.robot.links[link].inertial
        mass.CreateMassAttr(float(inertial.mass) if inertial is not None else 0.0)
        if inertial is None:
            return
        xyz = inertial.origin.xyz if inertial.origin is not None else (0.0, 0.0, 0.0)
        mass.CreateCenterOfMassAttr(Gf.Vec3f(*xyz))
        d, q = principal(inertial)
        if any(d):
            mass.CreateDiagonalInertiaAttr(Gf.Vec3f(*d))
            mass.CreatePrincipalAxesAttr(Gf.Quatf(q[0], Gf.Vec3f(q[1], q[2], q[3])))

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
                api = UsdPhysics.FilteredPairsAPI.Apply(self.stage.OverridePrim(self.link_path(a)))
                api.CreateFilteredPairsRel().SetTargets([self.link_path(b) for b in others])

    def _frame(self, joint: PhysicsJoint, parent: str, child: str, X_PJ: np.ndarray, X_CJ: np.ndarray,
               R_a: np.ndarray) -> None:
        joint.CreateBody0Rel().SetTargets([self.link_path(parent)])
        joint.CreateBody1Rel().SetTargets([self.link_path(child)])
        joint.CreateLocalPos0Attr(Gf.Vec3f(*map(float, X_PJ[:3, 3])))
        joint.CreateLocalRot0Attr(quatf(X_PJ[:3, :3] @ R_a))
        joint.CreateLocalPos1Attr(Gf.Vec3f(*map(float, X_CJ[:3, 3])))
        joint.CreateLocalRot1Attr(quatf(X_CJ[:3, :3] @ R_a))

    def joint(self, path: PrimPath, j: Joint) -> None:
        token, R_a = axis_frame(j.axis) if j.type in ONE_DOF else ("X", np.eye(3))
        usd_joint: PhysicsJoint
        if j.type in ("revolute", "continuous"):
            rev = UsdPhysics.RevoluteJoint.Define(self.stage, path)
            rev.CreateAxisAttr(token)
            lim = j.limit
            if j.type == "revolute" and lim is not None and (lim.lower is not None or lim.upper is not None):
                rev.CreateLowerLimitAttr((lim.lower or 0.0) * DEG)
                rev.CreateUpperLimitAttr((lim.upper or 0.0) * DEG)
            usd_joint = rev
        elif j.type == "prismatic":
            pri = UsdPhysics.PrismaticJoint.Define(self.stage, path)
            pri.CreateAxisAttr(token)
            lim = j.limit
            if lim is not None and (lim.lower is not None or lim.upper is not None):
                pri.CreateLowerLimitAttr(lim.lower or 0.0)
                pri.CreateUpperLimitAttr(lim.upper or 0.0)
            usd_joint = pri
        else:
            usd_joint = UsdPhysics.FixedJoint.Define(self.stage, path)
        _name(usd_joint.GetPrim(), j.name)
        self._frame(usd_joint, j.parent, j.child, pose_matrix(j.origin), np.eye(4), R_a)
        self.drive(usd_joint.GetPrim(), j)
        self.dynamics(usd_joint.GetPrim(), j)

    def dynamics(self, prim: Prim, j: Joint) -> None:
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
        prim.AddAppliedSchema("NewtonJointAPI")
        for name, value in given:
            prim.CreateAttribute(name, Sdf.ValueTypeNames.Float, custom=False).Set(value)

    def drive(self, prim: Prim, j: Joint) -> None:
        """The motor of a one-degree-of-freedom joint as a DriveAPI (see the module)."""
        motors = [m for m in (self.robot.motors[n] for n in sorted(self.robot.motors)) if m.joint == j.name]
        if not motors or j.type not in ONE_DOF:
            return
        settings = motors[0].settings
        angular = j.type != "prismatic"
        per = math.pi / 180 if angular else 1.0  # N·m/rad → N·m/degree
        drive = UsdPhysics.DriveAPI.Apply(prim, "angular" if angular else "linear")
        drive.CreateTypeAttr("force")
        for key, create in (("p", drive.CreateStiffnessAttr), ("d", drive.CreateDampingAttr)):
            value = settings.get(key)
            if isinstance(value, int | float) and not isinstance(value, bool):
                create(float(value) * per)
        effort = j.limit.effort if j.limit is not None else None
        if effort:
            drive.CreateMaxForceAttr(abs(effort))

    def mimic(self, folder: PrimPath, j: Joint) -> None:
        """NewtonMimicAPI on a one-degree-of-freedom joint that follows another of the same kind."""
        m = j.mimic
        leader = self.robot.joints.get(m.joint) if m is not None else None
        if m is None or not mimic_written(j, leader):
            return
        prim = self.stage.GetPrimAtPath(folder.AppendChild(self.joint_names[j.name]))
        prim.AddAppliedSchema("NewtonMimicAPI")
        prim.CreateRelationship("newton:mimicJoint", custom=False).SetTargets(
            [folder.AppendChild(self.joint_names[m.joint])])
        offset = (m.offset or 0.0) * (DEG if j.type != "prismatic" else 1.0)
        prim.CreateAttribute("newton:mimicCoef0", Sdf.ValueTypeNames.Float, custom=False).Set(offset)
        prim.CreateAttribute("newton:mimicCoef1", Sdf.ValueTypeNames.Float, custom=False).Set(
            1.0 if m.multiplier is None else m.multiplier)

    def cut(self, path: PrimPath, c: CutJoint) -> None:
        """A loop closure: a joint excluded from the articulation, at the closure's frame on
        both sides (mjcf.cut_sites)."""
        _, on_parent, on_child = cut_sites(c)[0]
        R_a = np.eye(3)
        if c.type == "fixed":
            joint: PhysicsJoint = UsdPhysics.FixedJoint.Define(self.stage, path)
        elif c.type == "ball":
            joint = UsdPhysics.SphericalJoint.Define(self.stage, path)
        else:
            axis = closed_cut_axis(c)
            assert axis is not None
            # the axis is in the child link's frame; the joint frame's own axis is R_CJᵀ·a
            R_CJ = pose_matrix(on_child)[:3, :3]
            token, R_a = axis_frame(tuple(float(x) for x in R_CJ.T @ np.asarray(axis)))  # type: ignore[arg-type]
            rev = UsdPhysics.RevoluteJoint.Define(self.stage, path)
            rev.CreateAxisAttr(token)
            joint = rev
        joint.CreateExcludeFromArticulationAttr(True)
        _name(joint.GetPrim(), c.name)
        self._frame(joint, c.parent, c.child, pose_matrix(on_parent), pose_matrix(on_child), R_a)


def _material_key(m: Material) -> tuple[object, ...]:
    return (m.name, m.rgba, m.emissive)


def _name(prim: Prim, name: str) -> None:
    prim.CreateAttribute(NAME, Sdf.ValueTypeNames.String, custom=True).Set(name)


def _place(xform: Xformable, xyz: np.ndarray | tuple[float, ...], R: np.ndarray,
           scale: tuple[float, ...] | None = None) -> None:
    """translate and orient (doubles), and scale when given; only those not the identity."""
    if any(float(x) != 0 for x in xyz):
        xform.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*map(float, xyz)))
    if not np.array_equal(R, np.eye(3)):
        xform.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(quatd(R))
    if scale is not None and tuple(scale) != (1.0, 1.0, 1.0):
        xform.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*map(float, scale)))

