"""AST of `export_config`: one entry per output, told apart by `type`."""

from typing import Annotated, ClassVar, Literal

from mpc.compiler.schema.base import (
    BY_TYPE,
    ONE_OF,
    Before,
    Expr,
    FileName,
    FileSuffix,
    Node,
    OneOrMore,
    RelativeName,
)


class _Export(Node):
    TYPE_WORD: ClassVar[str] = "export type"


MeshFormat = Literal["stl", "obj", "dae", "bobj", "mars_obj", "input_type"]


class _Kinematic(_Export):
    """Options shared by the URDF, SDF and MJCF exports."""

    ALIASES: ClassVar[dict[str, str]] = {"add_floatingbase": "add_floating_base"}
    mesh_format: MeshFormat = "input_type"
    additional_meshes: Annotated[list[MeshFormat] | MeshFormat, ONE_OF] | None = None
    link_in_smurf: bool = False
    include_cut_joints: bool = False
    filename_suffix: FileSuffix = ""
    filename: FileName | None = None
    ros_pathes: bool = False
    copy_with_other_pathes: bool = False
    enforce_zero: bool = False
    add_floating_base: bool = False
    correct_inertials: bool = False
    float_fmt_dict: dict[str, str] | None = None
    provide_primitives: bool = False  # in Phobos's default preset; read by nothing (W0260)


class UrdfExport(_Kinematic):
    SECTION: ClassVar[str] = "a urdf export"
    type: Literal["urdf"]


class SdfExport(_Kinematic):
    SECTION: ClassVar[str] = "an sdf export"
    type: Literal["sdf"]
    # 1.9 unquoted is a number in YAML; it means the version all the same.
    version: Annotated[Literal["1.6", "1.7", "1.9"], Before(
        lambda v: str(v) if isinstance(v, float) else v)] = "1.9"


class MjcfExport(_Kinematic):
    SECTION: ClassVar[str] = "an mjcf export"
    type: Literal["mjcf"]
    actuators: Literal["motors", "position", "velocity", "motor", "none"] = "motors"
    scene: bool = False


class UsdExport(_Export):
    """OpenUSD with UsdPhysics (specs/exports.md, "usd")."""

    SECTION: ClassVar[str] = "a usd export"
    ALIASES: ClassVar[dict[str, str]] = {"add_floatingbase": "add_floating_base"}
    type: Literal["usd"]
    layout: Literal["layered", "single"] = "layered"
    filename: FileName | None = None
    filename_suffix: FileSuffix = ""
    add_floating_base: bool = False
    correct_inertials: bool = False


class SmurfExport(_Export):
    """SMURF is always written; the entry exists for old files and changes nothing."""

    SECTION: ClassVar[str] = "a smurf export"
    type: Literal["smurf"]


class PdfExport(_Export):
    SECTION: ClassVar[str] = "a pdf export"
    type: Literal["pdf"]


class RenderExport(_Export):
    SECTION: ClassVar[str] = "a render export"
    type: Literal["render"]
    views: OneOrMore = ["iso", "front", "side"]
    geometry: Literal["visual", "collision", "both"] = "visual"
    poses: OneOrMore = ["all"]
    size: list[int] = [640, 480]
    background: Annotated[str | list[Expr], ONE_OF] = "white"


class JointLimitsExport(_Export):
    SECTION: ClassVar[str] = "a joint_limits export"
    type: Literal["joint_limits"]
    joints: OneOrMore = ["ALL"]
    file_name: RelativeName = "joint_limits.yml"


class BrakingModel(Node):
    SECTION: ClassVar[str] = "braking_model"
    linearFactor: Expr = 0  # the language's spelling
    invDeceleration: Expr = 0
    uncertainty: Expr = 0
    latency: Expr = 0


class KccdExport(_Export):
    SECTION: ClassVar[str] = "a kccd export"
    type: Literal["kccd"]
    join_before_convexhull: bool = True
    remove_joints: list[str] = []
    merge_additionally: list[str] = []
    keep_stls: bool = False
    keep_urdf: bool = False
    dirname: str = "kccd"  # a folder inside the output: E0521 when lowering
    reduce_meshes: Expr | None = None
    edit_collisions: dict[str, dict[str, Annotated[int | str, ONE_OF]]] = {}
    braking_model: BrakingModel | None = None
    simplify_swept_from: list[str] = []
    safety_distance: Expr = 0
    report_up_to: Expr = 0
    computation_budget: Expr = -1
    max_approximation_order: int = 1
    no_collision_between: dict[str, list[str]] = {}


class SubmodelExport(_Export):
    SECTION: ClassVar[str] = "a submodel export"
    type: Literal["submodel"]
    name: FileName
    start: str | None = None
    stop: OneOrMore | None = None
    include_unstopped_branches: bool = False
    no_submechanisms: bool = False
    abstract_model: bool = False
    include_human_in_abstract: bool = False
    remove_fixed: bool = False
    remove_joints: OneOrMore = []
    remove_links: OneOrMore = []
    move_joint_axis_to_intersection: dict[str, list[str]] = {}
    name_replacements: dict[str, str] = {}
    add_floating_base: bool = False
    filename: FileName | None = None
    only_urdf: bool = False
    export_config: list["ExportEntry"] | None = None


# Told apart by `type` (compiler/schema/base.py: BY_TYPE).
ExportEntry = Annotated[UrdfExport | SdfExport | MjcfExport | UsdExport | SmurfExport | PdfExport
                        | RenderExport | JointLimitsExport | KccdExport | SubmodelExport, BY_TYPE]
