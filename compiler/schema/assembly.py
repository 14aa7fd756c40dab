"""AST of `input_models` and `assemble`: where models come from and how they are joined."""

from typing import Annotated, Any, ClassVar, Literal

from mpc.compiler.schema.base import Before, Expr, JsonSchema, Length, Node, OneOrMore, Vec3

JointTypeName = Literal["revolute", "continuous", "prismatic", "fixed", "floating", "planar",
                        "ball", "universal", "screw", "revolute2"]


def _dict_or_list_of_dicts(value: Any) -> Any:
    """Replacements are a mapping or a list of one-entry mappings (applied in order)."""
    if isinstance(value, dict):
        return [{k: v} for k, v in value.items()]
    return value


_STR_MAP = {"type": "object", "additionalProperties": {"type": "string"}}
Replacements = Annotated[list[dict[str, str]], Before(_dict_or_list_of_dicts),
                         JsonSchema({"anyOf": [_STR_MAP, {"type": "array", "items": _STR_MAP}]})]


class Repo(Node):
    """An input model (or compare model) in a git repository, at a commit or branch."""

    SECTION: ClassVar[str] = "repo"
    ALIASES: ClassVar[dict[str, str]] = {"urdf_in_repo": "model_in_repo"}
    git: str
    commit: str | None = None
    branch: str | None = None
    model_in_repo: str
    submechanisms_in_repo: str | None = None


class InputModel(Node):
    """An entry of `input_models`: exactly one of basefile, derived_base, repo."""

    SECTION: ClassVar[str] = "an input model"
    basefile: str | None = None
    derived_base: str | None = None
    repo: Repo | None = None
    is_human: bool = False
    xacro_args: dict[str, Any] | None = None  # scalars each, checked when lowered (E0240)
    xacro_env: list[str] | None = None  # the environment variables its xacro may read

    def problem(self) -> str | None:
        given = [k for k in ("basefile", "derived_base", "repo") if getattr(self, k) is not None]
        if len(given) != 1:
            return ("an input model needs exactly one of 'basefile', 'derived_base' or "
                    f"'repo', got {' and '.join(given) or 'none'}")
        return None


class NameEditing(Node):
    """Prefixes, suffixes and regular-expression replacements of names.

    The unscoped keys apply to links, joints, collisions, visuals and submechanisms;
    the scoped ones (`link_prefix`, …) to one kind. Replacements apply in order.
    """

    SECTION: ClassVar[str] = "name_editing"
    ALIASES: ClassVar[dict[str, str]] = {
        f"submechanisms_{k}": f"submechanism_{k}" for k in ("prefix", "suffix", "replacements")}
    prefix: str | None = None
    suffix: str | None = None
    replacements: Replacements | None = None
    link_prefix: str | None = None
    link_suffix: str | None = None
    link_replacements: Replacements | None = None
    joint_prefix: str | None = None
    joint_suffix: str | None = None
    joint_replacements: Replacements | None = None
    collision_prefix: str | None = None
    collision_suffix: str | None = None
    collision_replacements: Replacements | None = None
    visual_prefix: str | None = None
    visual_suffix: str | None = None
    visual_replacements: Replacements | None = None
    submechanism_prefix: str | None = None
    submechanism_suffix: str | None = None
    submechanism_replacements: Replacements | None = None
    joint_equals_link_name: bool = False
    append_link_suffix: Literal["ALWAYS", "NAME_DUPLICATES"] | None = None


class Mirror(Node):
    """Mirror a model at a plane through the root frame's origin."""

    SECTION: ClassVar[str] = "mirror"
    plane: Vec3 = [0, 1, 0]
    # true would be taken for 1; the language does not
    flip_axis: Annotated[Literal[0, 1, 2], Before(lambda v: str(v) if isinstance(v, bool) else v)] = 1
    exclude_meshes: OneOrMore = []
    name_replacements: Replacements | None = None


class AttachJoint(Node):
    """The joint that attaches a child model to its parent in `assemble`."""

    SECTION: ClassVar[str] = "an attaching joint"
    parent: str
    child: str | None = None
    name: str | None = None
    type: JointTypeName = "fixed"
    xyz: Vec3 | None = None
    rpy: Vec3 | None = None
    r2r_transform: Annotated[list[Annotated[list[Expr], Length(4, 4)]], Length(4, 4)] | None = None
    axis: Vec3 | None = None
    min: Expr | None = None
    max: Expr | None = None
    eff: Expr | None = None
    vel: Expr | None = None


class AssemblyEntry(Node):
    """What the root model and each child of `assemble` share."""

    model: str
    name_editing: NameEditing | None = None
    remove_beyond: OneOrMore | None = None
    take_leaf: str | None = None
    mirror: Mirror | None = None
    children: list["AssembleChild"] = []


class AssembleChild(AssemblyEntry):
    """A model attached to its parent part by `joint`."""

    SECTION: ClassVar[str] = "an assemble child"
    joint: AttachJoint


class Assemble(AssemblyEntry):
    """The `assemble` section: the root model and, recursively, its children."""

    SECTION: ClassVar[str] = "assemble"

