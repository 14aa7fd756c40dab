"""Ops on collisions, visuals, materials, sensors, poses, submechanisms and annotations.

Their `apply` is written by the model-editing work; until then `SUPPORTED` is False
and compiling a definition that uses them is a "not supported yet" error, while
`mpc check` already checks every name they use.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from mpc.compiler.diagnostics import did_you_mean
from mpc.ir.names import Names
from mpc.ir.ops import Effects, Op, Ref

Vec3 = tuple[float, float, float]
Annotations = Mapping[str, object]


def _link_or_collision(names: Names, name: str, effects: Effects, field_name: str) -> None:
    pool = names.links | names.all("collision")
    if name not in pool:
        effects.error("E0310", f"collisions refers to unknown link or collision '{name}'"
                      f"{did_you_mean(name, pool)}", field_name)


@dataclass(frozen=True, kw_only=True)
class EditMaterial(Op):
    """Edit material `name`, or create it; colours are rgba (0..1)."""

    WHAT = "material"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    name: str
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
        from dataclasses import replace

        return replace(names, materials=names.materials | {self.name})


@dataclass(frozen=True, kw_only=True)
class EditCollisions(Op):
    """Edit the collisions of link `target` (or the one collision named `target`).

    targets: several links (`$default`: all links but `exclude`) instead of one.
    remove: True removes them all; names or regular expressions remove those matching.
    shape: replace meshes by their bounding box, cylinder or sphere (oriented or not, scaled),
        their convex hull, or a convex decomposition.
    join: merge the link's collisions into one convex hull.
    """

    SUPPORTED = False
    target: str = ""
    exclude: tuple[str, ...] = ()
    remove: bool | tuple[str, ...] = False
    shape: str | None = None
    oriented: bool = True
    scale: float = 1.0
    join: bool = False
    bitmask: int | None = None
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        return tuple(Ref("link", n, "exclude") for n in self.exclude)

    def effect(self, names: Names, effects: Effects) -> Names:
        if self.target:
            _link_or_collision(names, self.target, effects, "target")
        return names


@dataclass(frozen=True, kw_only=True)
class AutoBitmask(Op):
    """Compute collision bitmasks so that no two collisions collide that must not.

    never: (a, b) pairs (links or collisions) that never collide; always: pairs that may.
    """

    SUPPORTED = False
    never: tuple[tuple[str, str], ...] = ()
    always: tuple[tuple[str, str], ...] = ()

    def effect(self, names: Names, effects: Effects) -> Names:
        for a, b in (*self.never, *self.always):
            _link_or_collision(names, a, effects, "")
            _link_or_collision(names, b, effects, "")
        return names


@dataclass(frozen=True, kw_only=True)
class EditVisuals(Op):
    """Edit the visuals of `targets` (all links but `exclude` when empty)."""

    WHAT = "visuals"

    SUPPORTED = False
    targets: tuple[str, ...] = ()
    exclude: tuple[str, ...] = ()
    remove: bool | tuple[str, ...] = False
    material: str | None = None
    annotations: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        refs = [Ref("link", n, "targets") for n in self.targets]
        refs += [Ref("link", n, "exclude") for n in self.exclude]
        if self.material:
            refs.append(Ref("material", self.material, "material"))
        return tuple(refs)


@dataclass(frozen=True, kw_only=True)
class AddSensor(Op):
    """A sensor: on `link` (or `joint`) for single-link types, over `targets` for the others.

    targets: joints (Joint*, MotorCurrent) or links (Node*); ("All",) for every movable joint.
    """

    WHAT = "sensor"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    type: str
    name: str
    link: str | None = None
    joint: str | None = None
    frame: str | None = None
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


@dataclass(frozen=True, kw_only=True)
class AddPose(Op):
    """A named joint configuration; `default` fills the movable joints not listed."""

    WHAT = "pose"

    SUPPORTED = False
    name: str
    positions: Mapping[str, float] = field(default_factory=dict)
    default: float | None = None

    def reads(self) -> tuple[Ref, ...]:
        return tuple(Ref("joint", j, f"positions/{j}") for j in self.positions)


@dataclass(frozen=True, kw_only=True)
class AddSubmechanism(Op):
    """A submechanism or exoskeleton (HyRoDyn) over joints of the robot.

    joints: every joint the definition names (spanning tree, active, independent, …).
    definition: the definition as written, for the submechanisms file.
    """

    WHAT = "submechanism"
    EFFECT_NEEDS_READS = False

    SUPPORTED = False
    name: str
    exoskeleton: bool = False
    joints: tuple[str, ...] = ()
    definition: Annotations = field(default_factory=dict)

    def reads(self) -> tuple[Ref, ...]:
        return tuple(Ref("joint", j, "joints") for j in self.joints)

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.with_other("submechanism", [self.name])


@dataclass(frozen=True, kw_only=True)
class SubmechanismsFile(Op):
    """Use the submechanisms file at `path` as it is."""

    SUPPORTED = False
    path: str


@dataclass(frozen=True, kw_only=True)
class AddAnnotations(Op):
    """A free annotation category `category` (SMURF `<robot>_<category>.yml`)."""

    SUPPORTED = False
    category: str
    content: Annotations = field(default_factory=dict)
