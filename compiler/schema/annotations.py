"""AST of sensors, poses, submechanisms, exoskeletons, annotations and post_processing."""

from typing import Annotated, Any, ClassVar, Literal

from mpc.compiler.schema.base import ONE_OF, Expr, Field, Length, Node, OneOrMore, Vec3
from mpc.compiler.schema.editing import ConstraintAxis

SINGLE_LINK_SENSORS = ("Joint6DOF", "CameraSensor", "RotatingRaySensor", "IMU", "GPS")
MULTI_LINK_SENSORS = ("JointPosition", "JointVelocity", "MotorCurrent", "NodePosition",
                      "NodeRotation", "NodeContact", "NodeContactForce", "NodeCOM")
SensorType = Literal["Joint6DOF", "CameraSensor", "RotatingRaySensor", "IMU", "GPS",
                     "JointPosition", "JointVelocity", "MotorCurrent", "NodePosition",
                     "NodeRotation", "NodeContact", "NodeContactForce", "NodeCOM"]


class SensorDef(Node):
    """A sensor: single-link types name a `link` (or `joint`), multi-link types `targets`.

    type: required in the list form; in the mapping form (`sensors: {IMU: {...}}`) it is
    the key. Type-specific settings (resolution, rate, …) are kept as annotations.
    """

    SECTION: ClassVar[str] = "a sensor"
    ANNOTATIONS: ClassVar[bool] = True
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Any]
    type: SensorType | None = None
    name: str
    link: str | None = None
    joint: str | None = None
    frame: str | None = None
    targets: OneOrMore | None = None
    position_offset: Vec3 | None = None
    orientation_offset: Annotated[list[Expr], Length(3, 4)] | None = None


# The section is a list of sensors or a mapping type → sensor(s); validated as the form it has.
SensorsSection = Annotated[
    list[SensorDef] | dict[SensorType, Annotated[SensorDef | list[SensorDef], ONE_OF]], ONE_OF]


def sensor_entries(section: SensorsSection) -> list[tuple[str | None, SensorDef]]:
    """(type, definition) for both forms of the section, in order."""
    if isinstance(section, list):
        return [(s.type, s) for s in section]
    out: list[tuple[str | None, SensorDef]] = []
    for kind, value in section.items():
        out.extend((kind, s) for s in (value if isinstance(value, list) else [value]))
    return out


class PoseDef(Node):
    """A named joint configuration: joint → position; `$default` fills the other joints."""

    SECTION: ClassVar[str] = "a pose"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, Expr]
    default: Expr | None = Field(None, alias="$default")


class PosesSection(Node):
    """`poses`: named poses; a number for `$default` (Phobos's form) is every pose's
    position of the movable joints it does not list, where the pose has no `$default`."""

    SECTION: ClassVar[str] = "poses"
    ENTRIES: ClassVar[bool] = True
    __entries__: dict[str, PoseDef]
    default: Expr | None = Field(None, alias="$default")


class LoopConstraint(Node):
    SECTION: ClassVar[str] = "a loop constraint"
    cut_joint: str
    predecessor_body: str
    successor_body: str
    constraint_axes: list[ConstraintAxis] = []


class Submechanism(Node):
    """A (parallel) submechanism in HyRoDyn's terms."""

    SECTION: ClassVar[str] = "a submechanism"
    name: str
    type: str
    contextual_name: str | None = None
    file_path: str | None = None
    jointnames_independent: list[str] = []
    jointnames_spanningtree: list[str] = []
    jointnames_active: list[str] = []
    jointnames: list[str] = []
    loop_constraints: list[LoopConstraint] = []
    multi_joint_dependencies: list[dict[str, Any]] = []
    auto_gen: bool = False


class Exoskeleton(Node):
    SECTION: ClassVar[str] = "an exoskeleton"
    name: str
    around: str | None = None
    contextual_name: str | None = None
    type: str | None = None
    jointnames_spanningtree: list[str] = []
    jointnames_dependent: list[str] = []
    jointnames_independent: list[str] = []
    jointnames_active: list[str] = []
    jointnames: list[str] = []


class AnnotationsSection(Node):
    """Free annotation categories, each written to SMURF as `<name>_<category>.yml`."""

    SECTION: ClassVar[str] = "annotations"
    named_annotations: dict[str, dict[str, Any]] = {}
    # a mapping (the category `annotations`), or Phobos's list of [category, content] pairs
    general_annotations: Annotated[dict[str, Any] | list[Annotated[list[Any], Length(2, 2)]], ONE_OF] = {}


class PostProcessing(Node):
    """A command run after export: an argument list, or a string run by a shell when `shell`."""

    SECTION: ClassVar[str] = "a post_processing command"
    cmd: Annotated[str | Annotated[list[str], Length(1)], ONE_OF]
    cwd: str | None = None
    shell: bool = False
    executable: str | None = None
    env: OneOrMore = []  # names of mpc's environment variables the command gets (commands.py)
