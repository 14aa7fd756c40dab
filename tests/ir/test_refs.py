"""Declared references (ir/refs.py): every string field of the IR's records that names an element
is typed as such, so that reads, renaming and name checks find it without being told.

A new string field of an op, of a robot element or of the model data beyond URDF fails
`test_every_string_field_is_declared_or_said_not_to_name_an_element` until it is either typed
(`LinkRef`, `JointName`, …) or listed in NOT_NAMES with the reason it names no element, or
names one in a way a type cannot say.
"""

from __future__ import annotations

import dataclasses
import re

from mpc.ir import extras, program, refs, robot
from mpc.ir.ops import import_all, joints
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
    # The program and its exports (ir/program.py): files, folders, repositories, formats, text.
    **{(cls, field): "a file or folder of the output, or its name" for cls, field in (
        ("UrdfExport", "filename"), ("SdfExport", "filename"), ("MjcfExport", "filename"),
        ("PdfExport", "filename"), ("JointLimitsExport", "file_name"), ("SmurfExport", "filename"),
        ("SmurfExport", "model_file"), ("SmurfExport", "additional_files"), ("KccdExport", "dirname"),
        ("UrdfExport", "additional_meshes"), ("SdfExport", "additional_meshes"),
        ("MjcfExport", "additional_meshes"), ("CommandExport", "cwd"), ("CommandExport", "executable"),
        ("CommandExport", "command"), ("Deployment", "keep_files"), ("Deployment", "add_lfs_track"),
        ("DeploySubmodule", "target"))},
    **{(cls, "submodel"): "a submodel (its folder), not an element" for cls in (
        "UrdfExport", "SdfExport", "MjcfExport", "PdfExport", "RenderExport", "JointLimitsExport",
        "SmurfExport", "KccdExport")},
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
}


def _classes() -> list[type]:
    found = [*import_all().values(), joints.Dependency, joints.JointValues]
    for module in (robot, extras, program):
        found += [c for c in vars(module).values() if isinstance(c, type) and dataclasses.is_dataclass(c)
                  and c.__module__ == module.__name__]
    return found


def _undeclared(classes: list[type]) -> list[str]:
    """The string fields of `classes` that neither declare what they name nor say why not."""
    out = []
    for cls in classes:
        declared = {name for name, _ in refs.shapes(cls)}
        for f in dataclasses.fields(cls):
            holds_text = re.search(r"\bstr\b|Annotations|Mapping\[str|\bAny\b", str(f.type))
            if holds_text and f.name not in declared and f.name not in OP_FIELDS \
                    and (cls.__name__, f.name) not in NOT_NAMES:
                out.append(f"{cls.__name__}.{f.name}: {f.type}")
    return out


def test_every_string_field_is_declared_or_said_not_to_name_an_element() -> None:
    undeclared = _undeclared(_classes())
    assert not undeclared, "type these as references (ir/refs.py) or say why not in NOT_NAMES"


def test_the_guard_finds_a_new_string_field_that_names_a_link() -> None:
    @dataclasses.dataclass(frozen=True)
    class NewExport:
        link: str = ""
        start: refs.LinkRef = ""

    assert _undeclared([NewExport]) == ["NewExport.link: str"]


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
