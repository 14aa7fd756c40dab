"""The definition language as JSON Schema (draft 2020-12), documented from specs/, for editors.

Input: the node classes of compiler/schema/ (their fields' types, `_shapes`) and the key tables
of specs/*.md. Output: the schema `mpc schema` prints and specs/model-definition.schema.json
holds (a test keeps the committed file equal to what this module generates). What it adds
to the shapes of the classes: closed sections (`additionalProperties: false`), the old spellings
(deprecated), titles a user knows (a section's name or a property's key, never a class
name), a description for every property taken from the key tables of
specs/ (meaning, type and default), and examples from the runnable examples of specs/.
It does not validate anything: compiler/schema/ does.

Point an editor at it with a first line
`# yaml-language-server: $schema=<path>/model-definition.schema.json`.
"""

from __future__ import annotations

import functools
import inspect
import json
import re
import types
import typing
from pathlib import Path
from typing import Any

SCHEMA_ID = "https://mpc.invalid/model-definition.schema.json"
SPECS = Path(__file__).resolve().parents[1] / "specs"

# Where specs/ describes each node's keys: (page, heading the table is under; None: any),
# optionally with the prefix its rows give the keys (`joint.parent`).
PAGES: dict[str, tuple[str, str | None, str]] = {
    "Definition": ("definition.md", None, ""),
    "ModelSection": ("*", None, ""),
    "InputModel": ("assembly.md", "input_models", ""),
    "Repo": ("assembly.md", "input_models", ""),
    "Assemble": ("assembly.md", "assemble", ""),
    "AssembleChild": ("assembly.md", "assemble", ""),
    "AttachJoint": ("assembly.md", "assemble", ""),
    "NameEditing": ("name_editing.md", None, ""),
    "Mirror": ("mirror.md", None, ""),
    "MaterialDef": ("materials.md", None, ""),
    "FramesSection": ("frames.md", "Section keys", ""),
    "FrameDef": ("frames.md", None, ""),
    "NewFrameJoint": ("frames.md", "A new frame", "joint."),
    "JointsSection": ("joints.md", "Section keys", ""),
    "JointDef": ("joints.md", "Entries", ""),
    "MimicDef": ("joints.md", "Entries", "mimic."),
    "MotorDef": ("joints.md", "Entries", "motor."),
    "Limits": ("joints.md", "Entries", ""),
    "ConstraintAxis": ("joints.md", "Entries", ""),
    "CollisionsSection": ("collisions.md", "Section keys", ""),
    "CollisionDef": ("collisions.md", "Entries", ""),
    "VisualsSection": ("visuals.md", None, ""),
    "VisualDef": ("visuals.md", None, ""),
    "SensorDef": ("sensors.md", None, ""),
    "PosesSection": ("poses.md", None, ""),
    "PoseDef": ("poses.md", None, ""),
    "Submechanism": ("submechanisms.md", None, ""),
    "Exoskeleton": ("submechanisms.md", None, ""),
    "LoopConstraint": ("submechanisms.md", None, ""),
    "AnnotationsSection": ("annotations.md", None, ""),
    "PostProcessing": ("post_processing.md", None, ""),
    "TestSection": ("test.md", None, ""),
    "Tolerances": ("test.md", None, ""),
    "CompareModel": ("test.md", None, ""),
    "DeploymentSection": ("deployment.md", "Keys", ""),
    "Submodule": ("deployment.md", None, ""),
    "MirrorDeployment": ("deployment.md", None, ""),
    "UrdfExport": ("exports.md", "Entries", ""),
    "SdfExport": ("exports.md", "Entries", ""),
    "MjcfExport": ("exports.md", "Entries", ""),
    "UsdExport": ("exports.md", "USD", ""),
    "SmurfExport": ("exports.md", "Entries", ""),
    "PdfExport": ("exports.md", "Entries", ""),
    "RenderExport": ("exports.md", None, ""),
    "JointLimitsExport": ("exports.md", "Entries", ""),
    "KccdExport": ("exports.md", "Entries", ""),
    "SubmodelExport": ("exports.md", "Entries", ""),
    "BrakingModel": ("exports.md", "Entries", ""),
}

# Keys whose meaning specs/ gives in prose rather than in a key table: the prose, condensed.
PROSE: dict[tuple[str, str], str] = {
    ("PosesSection", "default"): "Phobos's form: every pose's position of the movable joints it does not "
    "list, where the pose has no $default of its own",
    ("Definition", "model"): "the model: its names, inputs, assembly, edits, exports, tests and deployment",
    ("Repo", "git"): "the repository's address",
    ("Repo", "commit"): "the commit to check out (exactly this one)",
    ("Repo", "branch"): "the branch whose current head is checked out, when no commit is given",
    ("Repo", "model_in_repo"): "the model file inside the repository (old spelling: urdf_in_repo)",
    ("Repo", "submechanisms_in_repo"): "a submechanisms file inside the repository",
    ("Assemble", "model"): "the input model (a key of input_models) this entry is made from",
    ("AssembleChild", "model"): "the input model (a key of input_models) this entry is made from",
    ("Assemble", "name_editing"): "renames this entry's names (see name_editing)",
    ("AssembleChild", "name_editing"): "renames this entry's names (see name_editing)",
    ("Assemble", "remove_beyond"): "a link or a list of links: keeps every link up to and including "
    "these and removes what is below them (names after this entry's name editing)",
    ("AssembleChild", "remove_beyond"): "a link or a list of links: keeps every link up to and "
    "including these and removes what is below them (names after this entry's name editing)",
    ("Assemble", "take_leaf"): "a link: keeps the subtree rooted at it; it becomes the root",
    ("AssembleChild", "take_leaf"): "a link: keeps the subtree rooted at it; it becomes the root",
    ("Assemble", "mirror"): "mirrors this entry's model at a plane (see mirror)",
    ("AssembleChild", "mirror"): "mirrors this entry's model at a plane (see mirror)",
    ("Assemble", "children"): "the models attached to this one, each by its joint",
    ("AssembleChild", "children"): "the models attached to this one, each by its joint",
    ("AssembleChild", "joint"): "the joint that attaches this child to its parent entry",
    ("MimicDef", "joint"): "the joint this joint follows (alias joint_name)",
    ("MimicDef", "multiplier"): "q = multiplier · q_joint + offset. Default: 1",
    ("MimicDef", "offset"): "q = multiplier · q_joint + offset (rad or m). Default: 0",
    ("ConstraintAxis", "name"): "the constraint axis's name",
    ("ConstraintAxis", "axis"): "3 numbers: the axis the loop closure constrains",
    ("LoopConstraint", "cut_joint"): "the joint cut to open the loop",
    ("LoopConstraint", "predecessor_body"): "the link before the cut",
    ("LoopConstraint", "successor_body"): "the link after the cut",
    ("LoopConstraint", "constraint_axes"): "list of {name, axis}: the axes the closure constrains",
    ("Exoskeleton", "name"): "the exoskeleton's name",
    ("Exoskeleton", "around"): "the human model (an input with is_human) the exoskeleton is worn around",
    ("Exoskeleton", "jointnames_dependent"): "the exoskeleton's dependent joints",
    ("Submodule", "repo"): "the submodule's repository",
    ("Submodule", "target"): "its folder in the target repository",
    ("Submodule", "commit"): "the commit it is pinned at",
    ("Submodule", "branch"): "the branch it follows",
    ("MirrorDeployment", "repo"): "the mirror repository that gets a copy",
    ("MirrorDeployment", "branch"): "the mirror's branch. Default: develop",
    ("MirrorDeployment", "submodules"): "whether the mirror also gets the submodules. Default: false",
    ("MirrorDeployment", "merge_request"): "open a merge request on the mirror instead of pushing. "
    "Default: false",
    ("MirrorDeployment", "mr_mention"): "users mentioned in the mirror's merge request",
    ("MirrorDeployment", "mr_title"): "the mirror's merge request title",
    ("MirrorDeployment", "mr_target"): "the branch the mirror's merge request targets",
    ("Tolerances", "default"): "tolerance of torques and what no other tolerance covers. Default: 0.01",
    ("Tolerances", "mass"): "tolerance of masses (kg). Default: 0.01",
    ("Tolerances", "rad"): "tolerance of angles (rad). Default: 0.03",
    ("Tolerances", "distance"): "tolerance of positions (m). Default: 0.003",
    ("CompareModel", "git"): "the previous release's repository (give git or path)",
    ("CompareModel", "path"): "the previous release on disk (give git or path)",
    ("CompareModel", "branch"): "the branch of the previous release",
    ("CompareModel", "commit"): "the commit of the previous release",
    ("CompareModel", "model_in_repo"): "the model file in the previous release (old spelling: urdf_in_repo)",
    ("CompareModel", "submechanisms_in_repo"): "the submechanisms file in the previous release",
    ("CompareModel", "ignore_failing_tests_for"): "a pattern of changes for which failing tests do not fail "
    "the run",
    ("SmurfExport", "type"): "smurf: SMURF is written anyway; the entry is accepted for old files",
    ("PdfExport", "type"): "pdf: the kinematic tree as a graph",
    ("UrdfExport", "type"): "urdf: a URDF file",
    ("SdfExport", "type"): "sdf: an SDFormat file",
    ("MjcfExport", "type"): "mjcf: a MuJoCo model",
    ("UsdExport", "type"): "usd: OpenUSD with UsdPhysics",
    ("RenderExport", "type"): "render: pictures of the model",
    ("JointLimitsExport", "type"): "joint_limits: a file of the joints' limits",
    ("KccdExport", "type"): "kccd: the model for KCCD's collision checks",
    ("SubmodelExport", "type"): "submodel: a part of the model, written to submodels/<name>/",
    ("SdfExport", "version"): "the SDFormat version: \"1.6\", \"1.7\" or \"1.9\" (a string). Default: "
    "\"1.9\"",
    ("JointLimitsExport", "joints"): "ALL, ACTIVE, INDEPENDENT, ACTUATED, ABSTRACT, a submodel's name, "
    "or a list of joint names. Default: ALL",
    ("JointLimitsExport", "file_name"): "the file written (a relative path). Default: joint_limits.yml",
    ("SubmodelExport", "name"): "the submodel's name (required); written to submodels/<name>/",
    ("SubmodelExport", "start"): "the link the submodel starts at. Default: the root",
    ("SubmodelExport", "stop"): "link names, or regular expressions matched against whole link "
    "names, where the submodel stops. Default: the leaves",
    ("SubmodelExport", "include_unstopped_branches"): "also keep the branches that reach no stop. Default: "
    "false",
    ("SubmodelExport", "no_submechanisms"): "the submodel has no submechanisms. Default: false",
    ("SubmodelExport", "abstract_model"): "Phobos's abstract model: only the fixed joints and the "
    "submechanisms' independent joints stay. Default: false",
    ("SubmodelExport", "include_human_in_abstract"): "not built yet (E0202)",
    ("SubmodelExport", "remove_fixed"): "merge away every fixed joint. Default: false",
    ("SubmodelExport", "remove_joints"): "joint names or regular expressions: these joints are "
    "merged away (the child link joins its parent)",
    ("SubmodelExport", "remove_links"): "not built yet (E0202)",
    ("SubmodelExport", "move_joint_axis_to_intersection"): "{joint: [a, b]}: the joint's frame moves "
    "to where the axes of a and b meet at q = 0",
    ("SubmodelExport", "name_replacements"): "{pattern: replacement}: regular expressions applied "
    "to every name",
    ("SubmodelExport", "add_floating_base"): "hang the submodel from a floating joint. Default: false",
    ("SubmodelExport", "filename"): "the base name of its files. Default: its name",
    ("SubmodelExport", "only_urdf"): "accepted and does nothing, as in Phobos (W0523)",
    ("SubmodelExport", "export_config"): "the submodel's exports. Default: the model's entries "
    "without submodels",
    ("KccdExport", "join_before_convexhull"): "true: one hull of all the body's shapes; false: the "
    "union of one hull per shape. Default: true",
    ("KccdExport", "remove_joints"): "joint names: joints merged away. Default: []",
    ("KccdExport", "merge_additionally"): "joint names merged additionally. Default: []",
    ("KccdExport", "simplify_swept_from"): "links whose movable joints below KCCD treats with order 0. "
    "Default: []",
    ("KccdExport", "keep_stls"): "keep the hulls' STL files. Default: false",
    ("KccdExport", "keep_urdf"): "keep the URDF urdf2kccd read. Default: false",
    ("KccdExport", "dirname"): "the folder inside the output. Default: kccd",
    ("KccdExport", "reduce_meshes"): "the fraction of each hull's faces to remove, or a number of faces to "
    "keep (4 or more)",
    ("KccdExport", "edit_collisions"): "{body: {n_points: N}} or {body: {shape: box | cylinder | "
    "sphere | convex}}: kccdcoveriv's points for that body",
    ("KccdExport", "braking_model"): "linearFactor, invDeceleration, uncertainty, latency: numbers (0)",
    ("KccdExport", "safety_distance"): "the safety distance (m). Default: 0",
    ("KccdExport", "report_up_to"): "distances reported up to this (m). Default: 0",
    ("KccdExport", "computation_budget"): "Default: -1 (none)",
    ("KccdExport", "max_approximation_order"): "an integer. Default: 1",
    ("KccdExport", "no_collision_between"): "{link: [links]}: body pairs KCCD does not check",
    ("FrameDef", "joint"): "a new frame's joint: {parent, name, xyz, rpy, type, axis}",
    ("FrameDef", "axis"): "a new frame's joint axis belongs in `joint`; in the flat form an `axis` is an "
    "annotation",
    ("JointDef", "parent"): "with cut_joint: the loop-closure joint's parent link",
    ("JointDef", "child"): "with cut_joint: the loop-closure joint's child link",
    ("JointDef", "constraint_axes"): "with cut_joint: list of {name, axis}, the axes the closure constrains",
    ("MotorDef", "name"): "the motor's name. Default: <joint>_motor",
    ("MotorDef", "p"): "the controller's proportional gain",
    ("MotorDef", "i"): "the controller's integral gain",
    ("MotorDef", "d"): "the controller's derivative gain",
    ("MotorDef", "maxEffort"): "the motor's largest effort (N·m or N)",
    ("MotorDef", "maxSpeed"): "the motor's largest speed (rad/s or m/s)",
    ("ModelSection", "robotname"): "the robot's name (required): the name in the URDF and of the output "
    "files",
    ("ModelSection", "modelname"): "the model's name (required): the name of the output folder and the ROS "
    "package",
    ("ModelSection", "input_models"): "{name: input model}: the models the definition starts from "
    "(basefile, derived_base or repo); at least one",
    ("ModelSection", "assemble"): "how the input models are joined into one robot: the root entry "
    "names an input model, its children attach others",
    ("ModelSection", "frames"): "per-link operations and annotations, and new frames (alias links)",
    ("ModelSection", "annotations"): "free annotation categories, each written to the SMURF",
    ("ModelSection", "post_processing"): "commands run after export, in order",
    ("ModelSection", "swing_my_robot"): "accepted and does nothing (Phobos's swing_my_robot)",
    ("ModelSection", "test"): "how the model is tested against its previous release",
    ("ModelSection", "deployment"): "where the model goes: the target repository's merge request, "
    "kept files, submodules and mirror",
    ("BrakingModel", "linearFactor"): "a number. Default: 0",
    ("BrakingModel", "invDeceleration"): "a number (s²/rad). Default: 0",
    ("BrakingModel", "uncertainty"): "a number. Default: 0",
    ("BrakingModel", "latency"): "a number (s). Default: 0",
}

TITLES = {"Definition": "model definition file", "ModelSection": "model",
          "UrdfExport": "URDF export", "SdfExport": "SDF export", "MjcfExport": "MJCF export",
          "UsdExport": "USD export", "SmurfExport": "SMURF export", "PdfExport": "PDF export"}


def definition_schema() -> dict[str, Any]:
    """The JSON Schema of a model definition file."""
    from mpc.compiler.schema import Definition
    from mpc.compiler.schema.base import Node

    defs = _shapes(Definition)
    # specs/ is beside the code in a checkout; an installed mpc without it describes less
    tables, examples = (_tables(), _examples()) if SPECS.is_dir() else ({}, {})
    classes = {c.__name__: c for c in _subclasses(Node)}
    for name, node in defs.items():
        cls = classes[name]
        node["title"] = TITLES.get(name) or re.sub(r"^(a|an|the) ", "", cls.SECTION) or name
        node["additionalProperties"] = node.get("additionalProperties", cls.ANNOTATIONS) \
            if cls.ENTRIES else False
        props = node.get("properties", {})
        for key, prop in props.items():
            _untitle(prop)
            prop["title"] = key  # what the user wrote: the heading of a hover
            prop["description"] = _describe(name, key, tables) or prop.get("description", "")
            if "`" in prop["description"]:  # editors that render markdown show it as code
                prop["markdownDescription"] = prop["description"]
            if name == "ModelSection" and key in examples:
                prop["examples"] = [examples[key]]
        for alias, target in cls.ALIASES.items():  # old spellings: same schema, deprecated
            if target in props:
                props[alias] = {**{k: v for k, v in props[target].items() if k != "markdownDescription"},
                                "deprecated": True, "title": alias,
                                "description": f"old spelling of '{target}'"}
            if target in node.get("required", []):
                node["required"].remove(target)
                either = [{"required": [target]}, {"required": [alias]}]
                node.setdefault("allOf", []).append({"anyOf": either})
        if "additionalProperties" in node and isinstance(node["additionalProperties"], dict):
            _untitle(node["additionalProperties"])
    schema = _simplify(defs.pop("Definition"))
    schema["$defs"] = _simplify(dict(sorted(defs.items())))
    # `defaults` is resolved before validation (compiler/inherit.py), so the AST has no field.
    schema["properties"]["defaults"] = {
        "type": "string", "description": "a defaults file (relative to this file) whose "
        "`default_model` is merged under `model`"}
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$id"] = SCHEMA_ID
    schema["title"] = "mpc model definition"
    return schema


def _shapes(root: type) -> dict[str, dict[str, Any]]:
    """The JSON Schema of each node class `root` reaches, by class name: its properties by key,
    each of its field's type and default; the shapes other tools give such classes."""
    from mpc.compiler.schema.checking import resolved, wrapping

    defs: dict[str, dict[str, Any]] = {}

    def of_node(cls: type) -> dict[str, Any]:
        if cls.__name__ not in defs:
            defs[cls.__name__] = {}  # being made: the classes may refer to each other
            defs[cls.__name__] = node(cls)
        return {"$ref": f"#/$defs/{cls.__name__}"}

    def node(cls: Any) -> dict[str, Any]:
        props, required = {}, []
        for f in cls.fields().values():
            prop = of_type(f.annotation, f.names)
            if f.is_required():
                required.append(f.key)
            else:
                prop["default"] = f.default
            props[f.key] = prop
        out: dict[str, Any] = {"properties": props, "title": cls.__name__, "type": "object"}
        if required:
            out["required"] = required
        if cls.__doc__:
            out["description"] = inspect.cleandoc(cls.__doc__)
        if cls.ENTRIES:
            entry = cls.entry_type()
            out["additionalProperties"] = True if entry is Any else of_type(entry, {})
        return out

    def of_type(tp: Any, names: dict[str, Any]) -> dict[str, Any]:
        tp = resolved(tp, names)
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            source, *markers = typing.get_args(tp)
            shape = of_type(source, names)
            for below, marker in wrapping(source, markers):
                if hasattr(marker, "json_schema"):
                    shape = marker.json_schema(below, functools.partial(dict, shape))
            return shape
        if origin in (typing.Union, types.UnionType):  # a member that is a union: its members
            members = [of_type(m, names) for m in typing.get_args(tp)]
            return {"anyOf": [m for member in members
                              for m in (member["anyOf"] if set(member) == {"anyOf"} else [member])]}
        if origin is typing.Literal:
            values = list(typing.get_args(tp))
            kind = "integer" if isinstance(values[0], int) else "string"
            return {"const": values[0], "type": kind} if len(values) == 1 else {"enum": values, "type": kind}
        if origin is list:
            return {"items": of_type(typing.get_args(tp)[0], names), "type": "array"}
        if origin is dict:
            key, value = typing.get_args(tp)
            out = {"additionalProperties": True if value is Any else of_type(value, names), "type": "object"}
            if typing.get_origin(key) is typing.Literal:
                out["propertyNames"] = {"enum": list(typing.get_args(key))}
            return out
        if tp is type(None):
            return {"type": "null"}
        if hasattr(tp, "fields"):
            return of_node(tp)
        return {Any: {}, str: {"type": "string"}, bool: {"type": "boolean"}, int: {"type": "integer"}}[tp]

    of_node(root)
    return defs


def render() -> str:
    """The schema as the committed file holds it: sorted keys, two-space indent."""
    return json.dumps(definition_schema(), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def _subclasses(cls: type) -> list[type]:
    out = []
    for sub in cls.__subclasses__():
        out += [sub, *_subclasses(sub)]
    return out


_TYPED = {"array": {"items", "minItems", "maxItems"}, "string": {"minLength", "maxLength"},
          "object": {"additionalProperties", "propertyNames", "minProperties"}}


def _simplify(schema: Any) -> Any:
    """`anyOf` of members of distinct types as one schema (`type: [number, string, null]`) or
    as `oneOf`: the same language, and editors show the property once, not once per member
    (the YAML language server hovered `eff` as `Eff || Eff || Eff || Eff`)."""
    if isinstance(schema, dict):
        schema = {k: _simplify(v) for k, v in schema.items()}
        members = schema.get("anyOf")
        if isinstance(members, list):
            kinds = [m.get("type") if "$ref" not in m else "object" for m in members]
            if all(isinstance(k, str) for k in kinds) and len(set(kinds)) == len(kinds):
                if all("$ref" not in m and set(m) - {"type"} <= _TYPED.get(k, set())
                       for m, k in zip(members, kinds, strict=True)):
                    del schema["anyOf"]
                    for m in members:
                        schema.update({k: v for k, v in m.items() if k != "type"})
                    schema["type"] = kinds
                else:
                    schema["oneOf"] = schema.pop("anyOf")
        return schema
    if isinstance(schema, list):
        return [_simplify(v) for v in schema]
    return schema


def _untitle(schema: Any) -> None:
    """Drop titles (class names) from a property and what it nests."""
    if isinstance(schema, dict):
        schema.pop("title", None)
        for key in ("anyOf", "oneOf", "allOf", "items", "additionalProperties", "prefixItems"):
            value = schema.get(key)
            for part in value if isinstance(value, list) else [value]:
                if isinstance(part, dict) and "$ref" not in part:
                    _untitle(part)


# -- specs/ ----------------------------------------------------------------------------------

Row = dict[str, str]


def _tables() -> dict[str, list[tuple[str, str, Row]]]:
    """page → [(heading, key token, row)] of every key table (a first column of `keys`)."""
    out: dict[str, list[tuple[str, str, Row]]] = {}
    for page in sorted(SPECS.glob("*.md")):
        heading, header, rows = "", None, out.setdefault(page.name, [])
        for line in page.read_text().splitlines():
            line = line.strip()
            if line.startswith("#"):
                heading, header = line.lstrip("#").strip(), None
            elif not line.startswith("|"):
                header = None
            elif header is None:
                header = [c.strip() for c in _cells(line)]
            elif not line.startswith("|---"):
                cells = dict(zip(header, (c.strip() for c in _cells(line)), strict=False))
                first = cells.get(header[0], "")
                for token in re.findall(r"`([^`]+)`", first.split(" (alias")[0]):
                    rows.append((heading, re.split(r"[:\s]", token)[0], cells))
    return out


def _intros() -> dict[str, str]:
    """Section key → the first paragraph of the page about it (`# Joints (`joints`)`)."""
    out = {}
    for page in sorted(SPECS.glob("*.md")):
        title, _, rest = page.read_text().partition("\n")
        paragraph = " ".join(rest.strip().split("\n\n")[0].split())
        for key in re.findall(r"`([a-z_]+)`", title.split("(", 1)[-1] if "(" in title else ""):
            out.setdefault(key, paragraph)
    return out


def _cells(line: str) -> list[str]:
    return re.split(r"(?<!\\)\|", line.strip().strip("|"))


def _describe(cls: str, key: str, tables: dict[str, list[tuple[str, str, Row]]]) -> str:
    if (cls, key) in PROSE:
        return PROSE[(cls, key)]
    if cls == "ModelSection" and key in (intros := _intros()):
        return intros[key]
    page, heading, prefix = PAGES.get(cls, ("*", None, ""))
    pages = [p for p in tables if page in ("*", p)]
    for p in pages:
        for h, token, row in tables[p]:
            if heading not in (None, h) and page != "*":
                continue
            if token == prefix + key or (token.endswith("…") and key.startswith(token[:-1])) or (
                    prefix and token == key):
                return _text(row)
    if not tables:
        return ""
    raise KeyError(f"specs/ does not describe {cls}.{key}: add it to a key table or to PROSE")


def _text(row: Row) -> str:
    meaning = row.get("meaning") or row.get("applies to") or ""
    parts = [meaning.replace("\\|", "|")] if meaning else []
    kind = row.get("type")
    if kind:
        parts.append(f"Type: {kind.replace(chr(92) + '|', '|')}.")
    default = row.get("default", "").strip()
    if default and default not in ("none", "—", "required"):
        parts.append(f"Default: {default}.")
    elif default == "required":
        parts.append("Required.")
    return " ".join(p if p.endswith(".") else p + "." for p in parts) or "."


def _examples() -> dict[str, Any]:
    """Model key → its value in the first runnable example of specs/ that sets it."""
    import yaml

    out: dict[str, Any] = {}
    for page in sorted(SPECS.glob("*.md")):
        for block in re.findall(r"```yaml\n(# example: .*?)```", page.read_text(), re.DOTALL):
            try:
                data = yaml.safe_load(block)
            except yaml.YAMLError:
                continue
            model = data.get("model") if isinstance(data, dict) else None
            if isinstance(model, dict):
                for key, value in model.items():
                    if page.stem.startswith(key.split("_")[0]) or key in page.read_text()[:200]:
                        out.setdefault(key, value)
    return out
