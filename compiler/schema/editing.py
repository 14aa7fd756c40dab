"""AST of the editing sections: materials, frames (links), joints, collisions, visuals.

Each section is keyed by the names it edits; `$keys` are section-wide settings.
Entries keep undeclared keys as free annotations for SMURF.
"""

from typing import Annotated, Any, ClassVar, Literal

from mpc.compiler.schema.assembly import JointTypeName, NameEditing
from mpc.compiler.schema.base import ONE_OF, Before, Expr, Field, Length, Node, OneOrMore, Vec3, str_or_list

Color = Annotated[list[Expr], Length(3, 4)]


class Transform(Node):
    """A rigid transform: translation xyz (m) and fixed-axis rpy (rad)."""

    SECTION: ClassVar[str] = "a transform"
    xyz: Vec3 = [0, 0, 0]
    rpy: Vec3 = [0, 0, 0]


class MaterialDef(Node):
    """Edit or create a material."""

    SECTION: ClassVar[str] = "a material"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    ALIASES: ClassVar[dict[str, str]] = {"diffuseColor": "diffuse", "ambientColor": "ambient",
                                         "specularColor": "specular", "emissionColor": "emissive",
                                         "diffuseTexture": "texture"}
    diffuse: Color | None = None
    ambient: Color | None = None
    specular: Color | None = None
    emissive: Color | None = None
    texture: str | None = None
    normalTexture: str | None = None  # the language's spelling
    shininess: Expr | None = None
    transparency: Expr | None = None


class NewFrameJoint(Node):
    """The joint of a new frame: its parent, pose and type."""

    SECTION: ClassVar[str] = "a new frame's joint"
    parent: str
    name: str | None = None
    xyz: Vec3
    rpy: Vec3
    type: JointTypeName = "fixed"
    axis: Vec3 | None = None


class FrameDef(Node):
    """Operations and annotations of one link; a name not in the robot is a new frame."""

    SECTION: ClassVar[str] = "a frame"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    ALIASES: ClassVar[dict[str, str]] = {"estimate_missing_com": "estimate_missing_coms"}
    transform_link: Transform | None = None
    transform_frame: Transform | None = None
    reparent_to: str | None = None
    make_root: bool = False
    estimate_missing_coms: bool | None = None
    estimate_missing_inertia: bool | None = None
    material: str | None = None
    name_editing: NameEditing | None = None
    # a new frame, given as `joint: {parent, xyz, rpy, type}` or flat (`parent`, `jointname`, …)
    joint: NewFrameJoint | None = None
    parent: str | None = None
    jointname: str | None = None
    xyz: Vec3 | None = None
    rpy: Vec3 | None = None
    axis: Vec3 | None = None
    type: JointTypeName | None = None
    mass: Expr | None = None

    def no_effect(self) -> list[tuple[str, str, str]]:
        if self.joint is None and self.parent is None:
            return []
        out = [("W0253", key, f"'{key}' has no effect on a new frame, which has no "
                f"{'visuals' if key == 'material' else 'collisions'} of its own")
               for key in ("material", "estimate_missing_coms", "estimate_missing_inertia")
               if getattr(self, key)]
        if self.joint is not None:
            out += [("W0257", key, f"'{key}' has no effect next to 'joint', which gives the new "
                     "frame's joint") for key in ("parent", "jointname", "xyz", "rpy", "axis", "type")
                    if key in self.given]
        return out


class FramesSection(Node):
    """`frames` (alias `links`): per-link operations, `$default` for every link."""

    SECTION: ClassVar[str] = "frames"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, FrameDef]
    default: FrameDef | None = Field(None, alias="$default")
    name_editing: NameEditing | None = Field(None, alias="$name_editing")


class MimicDef(Node):
    """This joint follows `joint`: q = multiplier · q_joint + offset."""

    SECTION: ClassVar[str] = "mimic"
    ALIASES: ClassVar[dict[str, str]] = {"joint_name": "joint"}
    joint: str
    multiplier: Expr = 1
    offset: Expr = 0


class MotorDef(Node):
    """A motor on a joint: name (default `<joint>_motor`), controller gains, annotations."""

    SECTION: ClassVar[str] = "a motor"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    name: str | None = None
    type: str | None = None
    p: Expr | None = None
    i: Expr | None = None
    d: Expr | None = None
    maxEffort: Expr | None = None  # the language's spelling
    maxSpeed: Expr | None = None


Active = Annotated[bool | MotorDef, ONE_OF]


class ConstraintAxis(Node):
    SECTION: ClassVar[str] = "a constraint axis"
    name: str | None = None
    axis: Vec3


class Limits(Node):
    """Joint limit values: positions (rad or m), effort, velocity."""

    SECTION: ClassVar[str] = "limits"
    min: Expr | None = None
    max: Expr | None = None
    eff: Expr | None = None
    vel: Expr | None = None


class JointDef(Node):
    """Settings of one joint; a `cut_joint` that does not exist yet is a loop closure."""

    SECTION: ClassVar[str] = "a joint"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    ALIASES: ClassVar[dict[str, str]] = {"lower": "min", "upper": "max", "effort": "eff",
                                         "velocity": "vel"}
    min: Expr | None = None
    max: Expr | None = None
    eff: Expr | None = None
    vel: Expr | None = None
    friction: Expr | None = None
    damping: Expr | None = None
    spring_stiffness: Expr | None = None
    spring_reference: Expr | None = None
    type: JointTypeName | None = None
    axis: Vec3 | None = None
    remove: bool = False
    cut_joint: bool = False
    parent: str | None = None
    child: str | None = None
    constraint_axes: list[ConstraintAxis] | None = None
    move_joint_axis_to_intersection: Annotated[list[str], Length(2, 2)] | None = None
    mimic: MimicDef | None = None
    movement_depends_on: Annotated[list[MimicDef], Before(
        lambda v: [v] if isinstance(v, dict) else v)] | None = None
    active: Active | None = None
    motor: MotorDef | None = None
    name_editing: NameEditing | None = None

    def no_effect(self) -> list[tuple[str, str, str]]:
        # what is set to false or nothing asks for nothing (`active: false` on a cut joint)
        given = [k for k, n in self.declared().items() if n in self.given and getattr(self, n)]
        given += list(self.entries)
        if self.cut_joint:
            return [("W0251", k, f"'{k}' has no effect on a cut joint, which takes only 'parent', "
                     "'child', 'type', 'constraint_axes' and annotations")
                    for k in given if k in self.declared() and k not in _CUT_JOINT_KEYS]
        if self.remove:
            return [("W0250", k, f"'{k}' has no effect: the joint is removed ('remove: true')")
                    for k in given if k != "remove"]
        return [("W0252", k, f"'{k}' has no effect without 'cut_joint: true' (a joint's links "
                 "change with frames' reparent_to)") for k in ("parent", "child", "constraint_axes")
                if k in self.given]


_CUT_JOINT_KEYS = ("cut_joint", "parent", "child", "type", "constraint_axes", "remove")


class JointsSection(Node):
    """`joints`: per-joint settings plus section-wide `$keys`."""

    SECTION: ClassVar[str] = "joints"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, JointDef]
    default: JointDef | None = Field(None, alias="$default")
    replace_joint_types: dict[JointTypeName, JointTypeName] | None = Field(
        None, alias="$replace_joint_types")
    all: bool = Field(False, alias="$all")
    name_editing: NameEditing | None = Field(None, alias="$name_editing")
    backup: Limits | None = Field(None, alias="$backup")

    def no_effect(self) -> list[tuple[str, str, str]]:
        if self.all and self.default is None:
            return [("W0256", "$all", "'$all' has no effect without '$default', the values it "
                     "applies to every joint")]
        return []


def _exclude_without_default(section: Node) -> list[tuple[str, str, str]]:
    if "exclude" in section.given and section.default is None:  # type: ignore[attr-defined]
        return [("W0255", "$exclude", "'$exclude' has no effect without '$default': it names "
                 "the links that '$default' leaves out")]
    return []


RemoveWhat = Annotated[bool | list[str], ONE_OF, Before(
    lambda v: str_or_list(v) if isinstance(v, str) else v)]
ShapeName = Literal["box", "cylinder", "sphere", "convex", "convex_decomposition", "mesh", "remove"]


Join = Annotated[bool | Literal["union"], ONE_OF]


class CollisionDef(Node):
    """Operations and annotations of a link's collisions (or of one collision by name)."""

    SECTION: ClassVar[str] = "a collision entry"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    remove: RemoveWhat = False
    shape: ShapeName | None = None
    oriented: bool = True
    scale: Expr = 1
    join: Join = False
    bitmask: int | None = None
    ccfm: Expr | None = None


class CollisionsSection(Node):
    """`collisions`: per-link (or per-collision) entries, bitmasks, section-wide `$keys`."""

    SECTION: ClassVar[str] = "collisions"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, CollisionDef]
    default: CollisionDef | None = Field(None, alias="$default")
    exclude: OneOrMore = Field([], alias="$exclude")
    name_editing: NameEditing | None = Field(None, alias="$name_editing")

    def no_effect(self) -> list[tuple[str, str, str]]:
        return _exclude_without_default(self)
    auto_bitmask: bool = False
    apply_primitives: bool = False
    no_collision_between: dict[str, OneOrMore] = {}
    collision_between: dict[str, OneOrMore] = {}


class VisualDef(Node):
    """Operations and annotations of a link's visuals."""

    SECTION: ClassVar[str] = "a visual entry"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    remove: RemoveWhat = False
    material: str | None = None


class VisualsSection(Node):
    """`visuals`: per-link entries and section-wide `$keys`."""

    SECTION: ClassVar[str] = "visuals"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, VisualDef]
    default: VisualDef | None = Field(None, alias="$default")
    exclude: OneOrMore = Field([], alias="$exclude")
    name_editing: NameEditing | None = Field(None, alias="$name_editing")

    def no_effect(self) -> list[tuple[str, str, str]]:
        return _exclude_without_default(self)
