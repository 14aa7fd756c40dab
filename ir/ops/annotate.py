"""Ops on collisions, visuals, materials, sensors, poses, submechanisms and annotations.

An op whose `SUPPORTED` is False is checked by `mpc check` but cannot be compiled yet.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import field, replace

from mpc.core.diagnostics import did_you_mean
from mpc.core.record import record
from mpc.ir.extras import Sensor, Submechanism
from mpc.ir.names import Names
from mpc.ir.ops.base import Effects, Op, Phase, Ref
from mpc.ir.refs import JointRef, LinkRef, MaterialName, MaterialRef, PoseName, SensorName, SubmechanismName
from mpc.ir.robot import Collision, Material, Pose, Robot


def _matches(name: str | None, remove: bool | tuple[str, ...]) -> bool:
    """Whether a visual or collision named `name` is removed: all, or by name or pattern."""
    if remove is True:
        return True
    if not remove or name is None:
        return False
    return any(name == p or re.fullmatch(p, name) for p in remove)


def _rgba(colour: tuple[float, ...] | None) -> tuple[float, float, float, float] | None:
    if colour is None:
        return None
    return (*colour[:3], colour[3] if len(colour) > 3 else 1.0)  # type: ignore[return-value]

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


def _link_or_collision(names: Names, name: str, effects: Effects, field_name: str) -> None:
    pool = names.links | names.all("collision")
    if name not in pool:
        effects.error("E0310", f"collisions refers to unknown link or collision '{name}'"
                      f"{did_you_mean(name, pool)}", field_name)


@record(kw_only=True)
class EditMaterial(Op):
    """Edit material `name`, or create it; colours are rgba (0..1)."""

    PHASE = Phase.MATERIALS

    WHAT = "material"
    EFFECT_NEEDS_READS = False

    name: MaterialName
    diffuse: tuple[float, ...] | None = None
    ambient: tuple[float, ...] | None = None
    specular: tuple[float, ...] | None = None
    emissive: tuple[float, ...] | None = None
    texture: str | None = None
    normal_texture: str | None = None
    shininess: float | None = None
    transparency: float | None = None
    annotations: Annotations = field(default_factory=dict)

    def effect(self, names: Names, effects: Effects) -> Names:
        return replace(names, materials=names.materials | {self.name})

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        old = robot.materials.get(self.name) or Material(name=self.name, span=self.span)
        changes = {k: v for k, v in (
            ("rgba", _rgba(self.diffuse)), ("ambient", self.ambient), ("specular", self.specular),
            ("emissive", self.emissive), ("texture", self.texture), ("normal_texture", self.normal_texture),
            ("shininess", self.shininess), ("transparency", self.transparency)) if v is not None}
        material = replace(old, **changes, annotations={**old.annotations, **self.annotations})
        return replace(robot, materials={**robot.materials, self.name: material})


@record(kw_only=True)
class EditCollisions(Op):
    """Edit the collisions of link `target` (or the one collision named `target`).

    target: empty for every link but `exclude` (`$default`).
    remove: True removes them all; names or regular expressions remove those matching.
    shape: box, cylinder or sphere: the bounding primitive of each shape (`oriented`: the
        smallest in any orientation, else along the shape's axes; `scale` multiplies it);
        with `replace` (`apply_primitives`) it replaces the shape, otherwise it is recorded
        next to it as the `primitives` annotation (Phobos's meaning). `convex`: the mesh's
        convex hull. `remove`: as remove: true. `mesh`: unchanged.
    join: merge the link's collisions into one: True their convex hull, "union" their solid
        union (one closed mesh, concave where they are).
    phobos_default: the entry is `default`, which Phobos hands to its auto_bitmask (which
        ignores it): without a link or collision of that name it does nothing (W0263).
    """

    PHASE = Phase.COLLISIONS

    target: str = ""
    phobos_default: bool = False
    exclude: tuple[LinkRef, ...] = ()
    remove: bool | tuple[str, ...] = False
    shape: str | None = None
    oriented: bool = True
    scale: float = 1.0
    replace: bool = False
    join: bool | str = False
    bitmask: int | None = None
    annotations: Annotations = field(default_factory=dict)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.phobos_default and self.target not in names.links | names.all("collision"):
            effects.warning("W0263", f"collisions: '{self.target}' names no link or collision, so the entry "
                            "has no effect (Phobos hands it to its auto_bitmask, which ignores it); "
                            "'$default' edits every link's collisions", "target")
        elif self.target:
            _link_or_collision(names, self.target, effects, "target")
        return names

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        links = dict(robot.links)
        for name, link in robot.links.items():
            if self.target in ("", name):
                if not self.target and name in self.exclude:
                    continue
                chosen = lambda c: True  # noqa: E731
            elif any(c.name == self.target for c in link.collisions):
                chosen = lambda c: c.name == self.target  # noqa: E731
            else:
                continue
            kept = []
            for c in link.collisions:
                if not chosen(c):
                    kept.append(c)
                elif not _matches(c.name, self.remove) and self.shape != "remove":
                    edited = self._edit(c, name, effects)
                    if edited is not None and self.shape == "convex_decomposition":
                        kept.extend(_decomposed(edited, name, effects))
                    elif edited is not None:
                        kept.append(edited)
            if self.join and len(kept) > 1:
                joined = _join(self, name, kept, effects)
                kept = [joined] if joined is not None else kept
            links[name] = replace(link, collisions=tuple(kept))
        return replace(robot, links=links)

    def _edit(self, c: Collision, link: str, effects: Effects) -> Collision | None:
        from mpc.ir.geometry import ConvexHull, Mesh

        annotations = {**c.annotations, **self.annotations}
        c = replace(c, bitmask=self.bitmask if self.bitmask is not None else c.bitmask)
        if self.shape in ("box", "cylinder", "sphere"):
            primitive = self._primitive(c, link, effects)
            if primitive is None:
                return None
            if self.replace:
                return replace(primitive, annotations=annotations)
            annotations["primitives"] = [_describe(primitive)]
        elif self.shape == "convex" and isinstance(c.geometry, Mesh):
            c = replace(c, geometry=replace(c.geometry, ops=(*c.geometry.ops, ConvexHull())))
        return replace(c, annotations=annotations)

    def _primitive(self, c: Collision, link: str, effects: Effects) -> Collision | None:
        from mpc.ir.kinematics import matrix_pose, pose_matrix
        from mpc.ir.mesh_props import MeshError, bounding, scaled

        try:
            shape, X_GB = bounding(c.geometry, self.shape or "box", self.oriented)
        except MeshError as e:
            effects.error("E0602", f"collision of link '{link}': {e}", "target")
            return None
        return replace(c, geometry=scaled(shape, self.scale),
                       origin=matrix_pose(pose_matrix(c.origin) @ X_GB))


def _decomposed(c: Collision, link: str, effects: Effects) -> list[Collision]:
    """One collision per convex part of a mesh (coacd); primitives are convex already."""
    from mpc.ir.decompose import parts
    from mpc.ir.geometry import ConvexPart, Mesh
    from mpc.ir.mesh_props import MeshError, as_trimesh

    if not isinstance(c.geometry, Mesh):
        return [c]
    try:
        count = len(parts(c.geometry, as_trimesh))
    except MeshError as e:
        effects.error("E0602", f"convex decomposition of a collision of link '{link}': {e}", "target")
        return [c]
    base = c.name or f"{link}_collision"
    scale = c.geometry.scale
    return [replace(c, name=f"{base}_{i}", geometry=replace(c.geometry, scale=None,
                                                            ops=(*c.geometry.ops, ConvexPart(i, scale))))
            for i in range(count)]


def _join(op: EditCollisions, link: str, collisions: list[Collision], effects: Effects) -> Collision | None:
    """One collision: the convex hull of all of them (`join: true`) or their solid union
    (`join: union`, its repairs and convex-hull stand-ins reported now), in the frame of the
    first mesh."""
    from mpc.ir.geometry import ConvexHull, JoinShapes, Mesh, generated_source
    from mpc.ir.kinematics import compose_poses, inverse_pose
    from mpc.ir.ops.frames import collision_solid

    union = op.join == "union"
    if union and collision_solid(op, link, collisions, effects, "target") is None:
        return None

    meshes = [c for c in collisions if isinstance(c.geometry, Mesh)]
    # The first mesh names the result and gives its frame; of primitives alone, mpc makes a
    # mesh named after the link, in the frame of the first of them.
    first = meshes[0] if meshes else collisions[0]
    source = first.geometry.source if isinstance(first.geometry, Mesh) else generated_source(link)
    X_inv = inverse_pose(first.origin)
    parts = []
    for c in collisions:  # each part keeps its own scale (as_trimesh applies it)
        X = compose_poses(X_inv, c.origin)
        parts.append((c.geometry, X.xyz, X.rpy))
    mesh = Mesh(source=source, span=first.geometry.span if isinstance(first.geometry, Mesh) else None,
                ops=(JoinShapes(tuple(parts), solid=True),) if union
                else (JoinShapes(tuple(parts)), ConvexHull()))
    name = first.name if meshes else None
    return replace(first, name=name or f"{link}_joined", geometry=mesh,
                   annotations={k: v for c in collisions for k, v in c.annotations.items()})


def _describe(c: Collision) -> dict[str, object]:
    g = c.geometry
    origin = c.origin or Pose()
    pose = {"xyz": list(origin.xyz), "rpy": list(origin.rpy)}
    if hasattr(g, "size"):
        return {"type": "box", "size": list(g.size), "pose": pose}
    if hasattr(g, "length"):
        return {"type": "cylinder", "radius": g.radius, "length": g.length, "pose": pose}
    return {"type": "sphere", "radius": g.radius, "pose": pose}


@record(kw_only=True)
class AutoBitmask(Op):
    """Compute collision bitmasks so that no two links collide that must not (ir/bitmask.py).

    never: (a, b) pairs (links or collisions) that never collide; always: pairs that may.
    The result: each collision's `bitmask`, and the robot annotation `self_collision`
    listing the link pairs that may collide.
    """

    PHASE = Phase.COLLISIONS

    never: tuple[tuple[str, str], ...] = ()
    always: tuple[tuple[str, str], ...] = ()

    def effect(self, names: Names, effects: Effects) -> Names:
        for a, b in (*self.never, *self.always):
            _link_or_collision(names, a, effects, f"pair/{a}")
            _link_or_collision(names, b, effects, f"pair/{a}/{b}")
        return names

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        from itertools import combinations

        from mpc.ir.bitmask import BITS, assign, never_colliding, touching
        from mpc.ir.geometry import MeshError

        owner = {c.name: n for n, lk in robot.links.items() for c in lk.collisions if c.name}

        def pair(a: str, b: str) -> frozenset[str]:
            return frozenset((owner.get(a, a) if a not in robot.links else a,
                              owner.get(b, b) if b not in robot.links else b))

        links = [n for n, lk in robot.links.items() if lk.collisions]
        try:
            apart = never_colliding(robot) | touching(robot)
        except MeshError as e:
            effects.error("E0602", f"auto_bitmask: {e}")
            return robot
        apart |= {pair(a, b) for a, b in self.never}
        allowed = {frozenset(p) for p in combinations(links, 2)} - apart
        allowed |= {pair(a, b) for a, b in self.always}
        masks, lost = assign(links, allowed)
        if lost:
            effects.sink.warning(self.span, "W0304", f"auto_bitmask: {BITS} bits cannot let "
                                 f"{len(lost)} allowed pairs collide (e.g. "
                                 f"{' and '.join(sorted(next(iter(sorted(lost, key=sorted)))))}); "
                                 "they will not collide")
        new_links = dict(robot.links)
        for name in links:
            link = robot.links[name]
            new_links[name] = replace(link, collisions=tuple(replace(c, bitmask=masks[name])
                                                             for c in link.collisions))
        matrix = {"may_collide": sorted(sorted(p) for p in allowed - lost)}
        return replace(robot, links=new_links,
                       annotations={**robot.annotations, "self_collision": matrix})


@record(kw_only=True)
class EditVisuals(Op):
    """Edit the visuals of `targets` (all links but `exclude` when empty)."""

    PHASE = Phase.VISUALS

    WHAT = "visuals"

    targets: tuple[LinkRef, ...] = ()
    exclude: tuple[LinkRef, ...] = ()
    remove: bool | tuple[str, ...] = False
    material: MaterialRef | None = None
    annotations: Annotations = field(default_factory=dict)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        links = dict(robot.links)
        for name in self.targets or [n for n in robot.links if n not in self.exclude]:
            link = links[name]
            visuals = tuple(
                replace(v, material=self.material or v.material,
                        inline_material=None if self.material else v.inline_material,
                        annotations={**v.annotations, **self.annotations})
                for v in link.visuals if not _matches(v.name, self.remove))
            links[name] = replace(link, visuals=visuals)
        return replace(robot, links=links)


@record(kw_only=True)
class AddSensor(Op):
    """A sensor: on `link` (or `joint`) for single-link types, over `targets` for the others.

    targets: joints (Joint*, MotorCurrent) or links (Node*); ("All",) for every movable joint.
    """

    PHASE = Phase.SENSORS

    WHAT = "sensor"
    EFFECT_NEEDS_READS = False

    type: str
    name: SensorName
    link: LinkRef | None = None
    joint: JointRef | None = None
    frame: LinkRef | None = None
    targets: tuple[str, ...] = ()
    targets_kind: str = "joint"
    position_offset: Vec3 | None = None
    orientation_offset: tuple[float, ...] | None = None
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        refs = []
        if self.link:
            refs.append(Ref("link", self.link, "link"))
        if self.joint:
            refs.append(Ref("joint", self.joint, "joint"))
        if self.frame:
            refs.append(Ref("link", self.frame, "frame"))
        if self.targets != ("All",):
            refs += [Ref(self.targets_kind, n, "targets") for n in self.targets]  # type: ignore[arg-type]
        return tuple(refs)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.name in names.all("sensor"):
            effects.error("E0311", f"sensor '{self.name}' is defined twice", "name")
        return names.with_other("sensor", [self.name])

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        targets = self.targets
        if targets == ("All",):
            targets = tuple(n for n, j in robot.joints.items() if j.type != "fixed")
        sensor = Sensor(name=self.name, type=self.type, link=self.link, joint=self.joint, frame=self.frame,
                        targets=targets, position_offset=self.position_offset,
                        orientation_offset=self.orientation_offset, annotations=dict(self.annotations))
        return replace(robot, sensors={**robot.sensors, self.name: sensor})


@record(kw_only=True)
class AddPose(Op):
    """A named joint configuration; `default` fills the movable joints not listed."""

    PHASE = Phase.POSES

    WHAT = "pose"

    name: PoseName
    positions: Mapping[JointRef, float] = field(default_factory=dict)
    default: float | None = None

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.with_other("pose", [self.name])

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        """Values are clamped to the joint's limits (a warning says so); fixed joints are
        not configurations (a warning too)."""
        values: dict[str, float] = {}
        if self.default is not None:
            values = {n: self.default for n, j in robot.joints.items() if j.type != "fixed"}
        for joint_name, value in self.positions.items():
            joint = robot.joints[joint_name]
            if joint.type == "fixed":
                effects.sink.warning(self.span_of(f"positions/{joint_name}"), "W0303",
                                     f"pose '{self.name}' sets fixed joint '{joint_name}'; ignored")
                continue
            values[joint_name] = value
        for joint_name, value in list(values.items()):
            limit = robot.joints[joint_name].limit
            if limit is None or robot.joints[joint_name].type == "continuous":
                continue
            lo = limit.lower if limit.lower is not None else value
            hi = limit.upper if limit.upper is not None else value
            clamped = min(max(value, lo), hi)
            if clamped != value:
                effects.sink.warning(self.span_of(f"positions/{joint_name}"), "W0302",
                                     f"pose '{self.name}': {joint_name} = {value:g} is outside "
                                     f"[{lo:g}, {hi:g}] and is clamped to {clamped:g}")
                values[joint_name] = clamped
        return replace(robot, poses={**robot.poses, self.name: values})


@record(kw_only=True)
class AddSubmechanism(Op):
    """A submechanism or exoskeleton (HyRoDyn) over joints of the robot.

    joints: every joint the definition names (spanning tree, active, independent, …).
    links: every link it names (loop-constraint bodies, an exoskeleton's `around`).
    definition: the definition as written, for the submechanisms file.
    """

    PHASE = Phase.SUBMECHANISMS

    WHAT = "submechanism"
    EFFECT_NEEDS_READS = False

    name: SubmechanismName
    exoskeleton: bool = False
    joints: tuple[JointRef, ...] = ()
    links: tuple[LinkRef, ...] = ()
    definition: Annotations = field(default_factory=dict)

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.with_other("submechanism", [self.name])

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        item = Submechanism(name=self.name, exoskeleton=self.exoskeleton, definition=dict(self.definition))
        return replace(robot, submechanisms=(*robot.submechanisms, item))


@record(kw_only=True)
class SubmechanismsFile(Op):
    """Use the submechanisms file at `path` as it is."""

    PHASE = Phase.SUBMECHANISMS

    path: str

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        return replace(robot, submechanisms_file=self.path)


@record(kw_only=True)
class AddAnnotations(Op):
    """A free annotation category `category` (SMURF `<robot>_<category>.yml`)."""

    PHASE = Phase.ANNOTATIONS

    category: str
    content: Annotations = field(default_factory=dict)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        merged = {**robot.annotations.get(self.category, {}), **self.content}
        return replace(robot, annotations={**robot.annotations, self.category: merged})


@record(kw_only=True)
class CompleteSubmechanisms(Op):
    """Cover every joint no submechanism names (Phobos does this when any is given): each
    connected group of uncovered movable joints becomes a `serial` chain, each group of
    uncovered fixed joints a `fixed` chain, in depth-first order, marked `auto_gen`."""

    PHASE = Phase.SUBMECHANISMS

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        from mpc.ir.tree import depth_first

        covered: set[str] = set()
        for s in robot.submechanisms:
            for key in ("jointnames_spanningtree", "jointnames", "jointnames_independent",
                        "jointnames_active", "jointnames_dependent"):
                covered |= set(s.definition.get(key, ()))
        order = [j.name for j, _ in depth_first(robot) if j is not None]
        groups: list[tuple[bool, list[str]]] = []
        group_of: dict[str, int] = {}
        for name in order:
            if name in covered:
                continue
            joint = robot.joints[name]
            fixed = joint.type == "fixed"
            above = next((j for j in robot.joints.values() if j.child == joint.parent), None)
            if above is not None and above.name in group_of and groups[group_of[above.name]][0] == fixed:
                index = group_of[above.name]
            else:
                groups.append((fixed, []))
                index = len(groups) - 1
            groups[index][1].append(name)
            group_of[name] = index
        made = []
        for fixed, joints in groups:
            kind = "fixed" if fixed else "serial"
            name = f"{kind}_chain_{joints[0]}"
            definition: dict[str, object] = {"name": name, "contextual_name": name, "type": kind,
                                             "auto_gen": True, "jointnames": list(joints)}
            if not fixed:
                definition.update(jointnames_spanningtree=list(joints), jointnames_active=list(joints),
                                  jointnames_independent=list(joints))
            made.append(Submechanism(name=name, definition=definition))
        return replace(robot, submechanisms=(*robot.submechanisms, *made))
