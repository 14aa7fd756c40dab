"""Declared references (ir/refs.py): every string field of the IR's records that names an element
is typed as such, so that reads, renaming and name checks find it without being told.

A new field that may hold a string (`str`, `Any`, `object`, in any container or union), of an
op, of a robot element, of the model data beyond URDF, of the program or of any IR record these
hold, fails `test_every_string_field_is_declared_or_said_not_to_name_an_element` until it is
either typed (`LinkRef`, `JointName`, …) or listed in NOT_NAMES with the reason it names no
element, or names one in a way a type cannot say. Types are read resolved, as ir/refs.py reads
them: an alias or `Optional[…]` of a reference declares it (the tests at the end prove it
through check_names, the pass `mpc check` runs).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from enum import Enum
from pathlib import Path
from typing import Annotated, Any, Literal, Optional, Union, get_args, get_origin

import pytest

from mpc.compiler.passes import PassContext
from mpc.compiler.passes.check_names import check_names
from mpc.core.diagnostics import Severity, Sink
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir import extras, program, refs, robot
from mpc.ir.names import Names
from mpc.ir.ops import OPS, LoadModel, Op, Phase, import_all, joints
from mpc.ir.robot import Joint, Link, Mimic, Robot, Visual

# Fields of every op.
OP_FIELDS = {
    "part": "a part of the assembly (root, root/0, …), not an element",
    "spans": "field paths → spans",
}
# Free data as written in the definition: mpc does not interpret it (ir/rename.py renames
# the few keys of submechanism definitions and annotations the SMURF is known to hold).
FREE = "free data as written"
NOT_NAMES: dict[tuple[str, str], str] = {
    **{(cls, "annotations"): FREE for cls in (
        "JointDefaults", "EditJoint", "AddCutJoint", "EditMaterial", "EditCollisions", "EditVisuals",
        "AddSensor", "AddFrame", "AnnotateLinks", "Material", "Visual", "Collision", "Link", "Sensor",
        "CutJoint")},
    **{(cls, field): FREE for cls, field in (
        ("SetMotor", "settings"), ("Motor", "settings"), ("AddSubmechanism", "definition"),
        ("AddAnnotations", "content"), ("Robot", "submodel_definitions"))},
    **{(cls, field): "XML comments" for cls, field in (
        ("Material", "comments"), ("Link", "comments"), ("Link", "inner_comments"), ("Joint", "comments"),
        ("Joint", "inner_comments"), ("Robot", "header_comments"), ("Robot", "trailing_comments"))},
    **{(cls, "type"): "a joint, sensor or shape type" for cls in (
        "EditJoint", "AddCutJoint", "AddSensor", "Attach", "AddFrame", "Sensor", "CutJoint")},
    ("EditCollisions", "shape"): "a shape type", ("EditCollisions", "join"): "a mode (union)",
    ("ReplaceJointTypes", "mapping"): "joint type → joint type",
    ("AddCutJoint", "constraint_axes"): "names of constrained directions",
    ("CutJoint", "constraint_axes"): "names of constrained directions",
    ("EditMaterial", "texture"): "a file", ("EditMaterial", "normal_texture"): "a file",
    ("Material", "texture"): "a file", ("Material", "normal_texture"): "a file",
    ("SubmechanismsFile", "path"): "a file", ("Robot", "submechanisms_file"): "a file",
    ("Mirror", "exclude_meshes"): "mesh files",
    ("Mirror", "name_replacements"): "patterns", ("EditCollisions", "remove"): "names or patterns",
    ("EditVisuals", "remove"): "names or patterns",
    ("AddAnnotations", "category"): "an annotation category",
    ("LoadModel", "input"): "an input model", ("Attach", "child"): "a part of the assembly",
    ("Robot", "name"): "the robot's name", ("SetRobotName", "name"): "the robot's name",
    ("EditNames", "kinds"): "kinds of names", ("EditNames", "append_link_suffix"): "a mode",
    ("Attach", "suffixed"): "field names", ("AddSensor", "targets_kind"): "a kind of names",
    # Names of elements that a type cannot declare: the op reads them itself.
    ("EditNames", "only"): "names of the one kind in `kinds` (EditNames.reads)",
    ("AddSensor", "targets"): "joints or links by targets_kind, or All (AddSensor.reads)",
    ("Attach", "parent_written"): "the name before name editing, for messages (Attach.reads)",
    ("Attach", "child_written"): "the name before name editing, for messages",
    ("EditCollisions", "target"): "a link or collision; effect reports it (E0310)",
    ("AutoBitmask", "never"): "pairs of links or collisions; effect reports them",
    ("AutoBitmask", "always"): "pairs of links or collisions; effect reports them",
    ("CutJoint", "name"): "a loop joint's name; joint name editing leaves it (as before)",
    ("CommandExport", "env"): "names of environment variables a command gets",
    ("Input", "xacro_env"): "names of environment variables a xacro model may read",
    ("ModelTest", "limit_tolerances"): "names of figures (position, velocity, effort)",
    ("ModelTest", "mirrored"): "the two words of mirrored joint names (left, right), not names",
    # The program and its exports (ir/program.py): files, folders, repositories, formats, text.
    **{(cls, field): "a file or folder of the output, or its name" for cls, field in (
        ("UrdfExport", "filename"), ("SdfExport", "filename"), ("MjcfExport", "filename"),
        ("UsdExport", "filename"), ("PdfExport", "filename"), ("JointLimitsExport", "file_name"),
        ("SmurfExport", "filename"),
        ("SmurfExport", "model_file"), ("SmurfExport", "additional_files"), ("KccdExport", "dirname"),
        ("UrdfExport", "additional_meshes"), ("SdfExport", "additional_meshes"),
        ("MjcfExport", "additional_meshes"), ("CommandExport", "cwd"), ("CommandExport", "executable"),
        ("CommandExport", "command"), ("Deployment", "keep_files"), ("Deployment", "add_lfs_track"),
        ("DeploySubmodule", "target"))},
    **{(cls, "submodel"): "a submodel (its folder), not an element" for cls in (
        "UrdfExport", "SdfExport", "MjcfExport", "UsdExport", "PdfExport", "RenderExport",
        "JointLimitsExport", "SmurfExport", "KccdExport")},
    **{(cls, field): "a format or a ROS package" for cls, field in (
        ("UrdfExport", "mesh_format"), ("SdfExport", "mesh_format"), ("MjcfExport", "mesh_format"),
        ("UrdfExport", "float_formats"), ("SdfExport", "float_formats"), ("MjcfExport", "float_formats"),
        ("UrdfExport", "ros_package"), ("SdfExport", "ros_package"), ("UrdfExport", "copy_package"),
        ("SdfExport", "copy_package"), ("RosPackageExport", "package"), ("RosPackageExport", "version"),
        ("RosPackageExport", "description"), ("RosPackageExport", "license"), ("SmurfExport", "description"),
        ("SmurfExport", "version"), ("RenderExport", "views"))},
    **{(cls, field): "a repository, branch, commit or path in it" for cls, field in (
        ("RepoRef", "git"), ("RepoRef", "model_in_repo"), ("RepoRef", "commit"), ("RepoRef", "branch"),
        ("RepoRef", "submechanisms_in_repo"), ("CompareTarget", "git"), ("CompareTarget", "branch"),
        ("CompareTarget", "commit"), ("CompareTarget", "model_in_repo"),
        ("CompareTarget", "submechanisms_in_repo"), ("CompareTarget", "ignore_failing_tests_for"),
        ("DeploySubmodule", "repo"), ("DeploySubmodule", "commit"), ("DeploySubmodule", "branch"),
        ("DeployMirror", "repo"), ("DeployMirror", "branch"), ("DeployMirror", "mr_target"),
        ("Deployment", "mr_target_branch"))},
    **{(cls, field): "text of a merge request" for cls, field in (
        ("DeployMirror", "mr_mention"), ("DeployMirror", "mr_title"), ("Deployment", "mr_title"),
        ("Deployment", "mr_description"), ("Deployment", "mr_mention"))},
    ("Input", "name"): "an input model", ("Input", "xacro_args"): "xacro's arguments",
    ("Program", "inputs"): "input models", ("Program", "robotname"): "the robot's name",
    ("Program", "modelname"): "the model's name", ("ModelTest", "name"): "a test",
    ("SubmodelExport", "name"): "the submodel's name (its folder)",
    ("SubmodelExport", "stop"): "links or regular expressions (the submodel cut matches them)",
    ("SubmodelExport", "remove_joints"): "joints or regular expressions (the submodel cut matches them)",
    ("SubmodelExport", "name_replacements"): "patterns",
    ("JointLimitsExport", "joints"): "joints, or a selection (ALL, ACTIVE…): the export reads them",
    ("JointLimitsExport", "joints_of"): "a submodel", ("RenderExport", "poses"): "poses, or all",
    # Records the ops and the robot hold (found through their fields' types).
    **{(cls, "extra_attrs"): "XML attributes mpc does not model, kept as written" for cls in (
        "Robot", "Link", "Joint", "Visual", "Collision", "Limit", "Dynamics", "Box", "Cylinder", "Sphere",
        "Mesh")},
    ("Visual", "geometry_attrs"): "XML attributes mpc does not model, kept as written",
    ("Collision", "geometry_attrs"): "XML attributes mpc does not model, kept as written",
    ("NameRule", "prefix"): "text added to names", ("NameRule", "suffix"): "text added to names",
    ("NameRule", "replacements"): "patterns",
    **{("Fragment", field): "XML as read; a fragment records the names in it (FragmentRef)" for field in (
        "tag", "xml", "comments")},
    ("FragmentRef", "name"): "a link or joint by its `kind` field (ir/rename.py renames fragments)",
    ("FragmentRef", "attr"): "an XML attribute",
    ("MeshSource", "uri"): "a mesh file", ("MeshSource", "unresolved"): "a mesh file as written",
}


def _reachable(hint: Any, found: dict[type, None]) -> None:
    """Add every IR record class in a resolved type (and in its fields' types) to `found`."""
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        if hint in found or not hint.__module__.startswith("mpc.ir"):
            return
        found[hint] = None
        for sub in refs.type_hints(hint).values():
            _reachable(sub, found)
    for arg in get_args(hint):
        _reachable(arg, found)


def _classes() -> list[type]:
    """Every op, robot value and program record, and every IR record their fields hold."""
    roots = [*import_all().values(), joints.Dependency, joints.JointValues]
    for module in (robot, extras, program):
        roots += [c for c in vars(module).values() if isinstance(c, type) and dataclasses.is_dataclass(c)
                  and c.__module__ == module.__name__]
    found: dict[type, None] = {}
    for cls in roots:
        _reachable(cls, found)
    return list(found)


def _holds_text(hint: Any) -> bool:
    """Whether a value of this resolved type may hold a string that declares no reference."""
    if get_origin(hint) is Annotated:
        return not any(isinstance(m, refs.Ref) for m in hint.__metadata__) and _holds_text(get_args(hint)[0])
    if hint is Any or hint is object or (isinstance(hint, type) and issubclass(hint, str)
                                         and not issubclass(hint, Enum)):
        return True
    if get_origin(hint) is Literal:  # a fixed vocabulary, not a name
        return False
    if hasattr(hint, "__supertype__"):  # NewType
        return _holds_text(hint.__supertype__)
    return any(_holds_text(arg) for arg in get_args(hint) if arg is not Ellipsis)


def _undeclared(classes: list[type]) -> list[str]:
    """The fields of `classes` that may hold a string, declare no reference and do not say why."""
    out = []
    for cls in classes:
        declared = {name for name, _ in refs.shapes(cls)}
        for name, hint in refs.type_hints(cls).items():
            if _holds_text(hint) and name not in declared and name not in OP_FIELDS \
                    and (cls.__name__, name) not in NOT_NAMES:
                out.append(f"{cls.__name__}.{name}")
    return out


def test_every_string_field_is_declared_or_said_not_to_name_an_element() -> None:
    undeclared = _undeclared(_classes())
    assert undeclared == [], "type these as references (ir/refs.py) or say why not in NOT_NAMES"


def test_the_guard_finds_a_new_string_field_that_names_a_link() -> None:
    @dataclasses.dataclass(frozen=True)
    class NewExport:
        link: str = ""
        start: refs.LinkRef = ""
        frame: Optional[str] = None  # noqa: UP045
        extra: Mapping[str, object] = dataclasses.field(default_factory=dict)
        count: int = 0
        mode: Literal["a", "b"] = "a"
        ends: tuple[MovedLink, ...] = ()

    assert _undeclared([NewExport]) == ["NewExport.link", "NewExport.frame", "NewExport.extra"]


def test_names_in_free_data_are_declared_renamed_and_pruned() -> None:
    sm = extras.Submechanism(name="leg", definition={
        "jointnames_active": ["knee", "hip"], "around": "thigh",
        "loop_constraints": [{"predecessor_body": "thigh", "successor_body": "shin"}], "type": "serial"})
    assert [(r.kinds, name, path) for r, name, path in refs.refs(sm) if not r.defines] == [
        (("joint",), "knee", "definition/jointnames_active/0"),
        (("joint",), "hip", "definition/jointnames_active/1"), (("link",), "thigh", "definition/around"),
        (("link",), "thigh", "definition/loop_constraints/0/predecessor_body"),
        (("link",), "shin", "definition/loop_constraints/0/successor_body")]
    out = refs.renamed(sm, lambda kinds, name: f"l_{name}" if kinds == ("link",) else name.upper())
    loop = {"predecessor_body": "l_thigh", "successor_body": "l_shin"}
    assert out.definition == {"jointnames_active": ["KNEE", "HIP"], "around": "l_thigh", "type": "serial",
                              "loop_constraints": [loop]}
    pruned = refs.pruned(sm, lambda kind, name: kind == "joint" and name == "knee", "definition")
    assert pruned.definition["jointnames_active"] == ["hip"] and pruned.definition["around"] == "thigh"
    assert refs.pruned(sm, lambda kind, name: False, "definition") is sm
    assert refs.names_only(sm, lambda kind, name: name != "shin") is False


def test_no_reason_is_left_for_a_field_that_is_gone() -> None:
    fields = {(cls.__name__, f.name) for cls in _classes() for f in dataclasses.fields(cls)}
    assert set(NOT_NAMES) <= fields


def test_refs_lists_nested_references_with_their_paths() -> None:
    joint = Joint(name="elbow", type="revolute", parent="upper", child="lower", mimic=Mimic(joint="shoulder"))
    assert [(r.kinds, r.defines, name, path) for r, name, path in refs.refs(joint)] == [
        (("joint",), True, "elbow", "name"), (("link",), False, "upper", "parent"),
        (("link",), False, "lower", "child"), (("joint",), False, "shoulder", "mimic/joint")]


def test_renamed_follows_every_declaration_and_keeps_what_did_not_change() -> None:
    from mpc.ir.geometry import Box

    visual = Visual(geometry=Box(size=(1.0, 1.0, 1.0)), name="v", material="steel")
    link = Link(name="upper", visuals=(visual,))
    maps = {"link": {"upper": "arm_upper"}, "visual": {"v": "arm_v"}}
    out = refs.renamed(link, lambda kinds, name: maps.get(kinds[0], {}).get(name, name))
    assert out.name == "arm_upper" and out.visuals[0].name == "arm_v"
    assert out.visuals[0].material == "steel"
    untouched = Robot(name="r", root="base", links={}, joints={})
    assert refs.renamed(untouched, lambda kinds, name: name) is untouched


def test_an_op_reads_its_declared_references_in_field_order() -> None:
    from mpc.core.span import Span
    from mpc.ir.ops import AnnotateLinks

    op = AnnotateLinks(span=Span("d.yml", 1, 1, 1, 2), links=("a", "b"), material="steel")
    assert [(r.kind, r.name, r.field) for r in op.reads()] == [
        ("link", "a", "links/0"), ("link", "b", "links/1"), ("material", "steel", "material")]


# Ops that spell a reference another way (a local alias, Optional[...]): they register in OPS
# when defined, and are taken out again at once (the IR text and the op catalogue know only
# the real ops).
MovedLink = refs.LinkRef


@record(kw_only=True)
class _AliasedLinkOp(Op):
    PHASE = Phase.FRAMES
    WHAT = "aliased link op"
    link: MovedLink


@record(kw_only=True)
class _OptionalLinkOp(Op):
    PHASE = Phase.FRAMES
    WHAT = "optional link op"
    link: Optional[refs.LinkRef] = None  # noqa: UP045 (the spelling under test)


for _cls in (_AliasedLinkOp, _OptionalLinkOp):
    del OPS[_cls.kind]


def _check_names(op: Op) -> list[str]:
    """What check_names (the pass `mpc check` runs) reports for `op` on an arm base > upper."""
    at = Span("arm.ir", 1, 1, 1, 2)
    arm = Names(links=frozenset({"base", "upper"}), joints={"base2upper": ("base", "upper")}, root="base")
    inputs = {"arm": program.Input(name="arm", kind="basefile", path=Path("arm.urdf"), span=at)}
    prog = program.Program(robotname="r", modelname="r", inputs=inputs,
                           ops=(LoadModel(span=at, input="arm"), op), exports=(), span=at)
    sink = Sink()
    check_names(prog, PassContext(sink, lambda inp: arm, Severity.WARNING))
    return [f"{d.code} {d.span.line}:{d.span.col} {d.message}" for d in sink]


def test_a_link_typed_through_a_local_alias_is_checked() -> None:
    assert refs.shapes(_AliasedLinkOp) == (("link", ("ref", refs.Ref(("link",)))),)
    op = _AliasedLinkOp(span=Span("arm.ir", 2, 1, 2, 9), link="uper")
    assert _check_names(op) == [
        "E0310 2:1 aliased link op refers to unknown link 'uper'; did you mean 'upper'?"]


def test_a_link_typed_as_optional_is_checked() -> None:
    assert refs.shapes(_OptionalLinkOp) == (("link", ("ref", refs.Ref(("link",)))),)
    op = _OptionalLinkOp(span=Span("arm.ir", 3, 1, 3, 9), link="uper")
    assert _check_names(op) == [
        "E0310 3:1 optional link op refers to unknown link 'uper'; did you mean 'upper'?"]
    assert _check_names(_OptionalLinkOp(span=Span("arm.ir", 3, 1, 3, 9))) == []


def test_every_spelling_of_a_reference_declares_the_same_shape() -> None:
    link = ("ref", refs.Ref(("link",)))
    assert refs.shape_of(MovedLink) == refs.shape_of(Optional[refs.LinkRef]) == link  # noqa: UP045
    assert refs.shape_of(refs.LinkRef | None) == link
    assert refs.shape_of(tuple[MovedLink, ...]) == refs.shape_of(list[refs.LinkRef]) == ("seq", link)
    assert refs.shape_of(tuple[refs.LinkRef, refs.JointRef]) == (
        "items", (link, ("ref", refs.Ref(("joint",)))))
    assert refs.shape_of(Mapping[str, refs.LinkRef]) == ("map", None, link)
    assert refs.shape_of(str) is None and refs.shape_of(Optional[str]) is None  # noqa: UP045


def test_a_union_of_different_references_is_refused() -> None:
    with pytest.raises(TypeError, match="declares different things in one union"):
        refs.shape_of(Union[refs.LinkRef, refs.JointRef])  # noqa: UP007


def test_a_pair_of_references_is_read_and_renamed_item_by_item() -> None:
    @dataclasses.dataclass(frozen=True)
    class Pair:
        ends: tuple[refs.LinkRef, refs.JointRef] = ("", "")

    pair = Pair(ends=("upper", "elbow"))
    assert [(r.kinds, name, path) for r, name, path in refs.refs(pair)] == [
        (("link",), "upper", "ends/0"), (("joint",), "elbow", "ends/1")]
    out = refs.renamed(pair, lambda kinds, name: f"{kinds[0]}_{name}")
    assert out.ends == ("link_upper", "joint_elbow")


@dataclasses.dataclass(frozen=True)
class _Shape:  # records in a circle that hold no reference (as a mesh's ops hold shapes)
    inner: tuple[_Shape, ...] = ()


@dataclasses.dataclass(frozen=True)
class _Middle:  # holds a reference through a record that holds it back
    outer: _Outer | None = None


@dataclasses.dataclass(frozen=True)
class _Outer:
    middle: _Middle | None = None
    link: refs.LinkRef = ""


def test_records_in_a_circle_are_walked_only_when_one_of_them_holds_a_reference() -> None:
    assert refs.shapes(_Shape) == ()
    assert refs.shapes(_Middle) == (("outer", ("record",)),)
    value = _Middle(outer=_Outer(middle=_Middle(outer=_Outer(link="hand")), link="arm"))
    assert [(name, path) for _, name, path in refs.refs(value)] == [
        ("hand", "outer/middle/outer/link"), ("arm", "outer/link")]


def test_the_program_declares_the_links_its_exports_name() -> None:
    at = Span("d.yml", 1, 1, 1, 2)
    kccd = program.KccdExport(simplify_swept_from=("upper",), span=at)
    prog = program.Program(robotname="r", modelname="r", inputs={}, ops=(), exports=(kccd,), span=at)
    assert [(r.kinds, name, path) for r, name, path in refs.refs(prog)] == [
        (("link",), "upper", "exports/0/simplify_swept_from/0")]
