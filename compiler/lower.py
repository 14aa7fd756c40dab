"""AST → ir.Program: inputs resolved to files, ops in the order the language fixes.

Lowering reads no input model. It evaluates every number (compiler/expr.py), turns
name editing into rules, and emits, for each part of the assembly tree depth-first:
load, name editing, remove_beyond, take_leaf, mirror, then its children, then the
attach to its parent. Parts of the language that later versions will lower are
reported through `later` (an error for `compile`, a warning for `check`).
"""

from __future__ import annotations

import re
import shlex
from dataclasses import replace
from pathlib import Path
from typing import Any

from mpc.backends.packages import PackageResolver
from mpc.compiler.expr import evaluate
from mpc.compiler.lower_deploy import lower_model_deployment
from mpc.compiler.lower_edits import EditLowering
from mpc.compiler.lower_smurf import SmurfLowering
from mpc.compiler.schema import Definition
from mpc.compiler.schema.assembly import AssembleChild, AssemblyEntry, AttachJoint, NameEditing
from mpc.compiler.schema.base import Node
from mpc.core.diagnostics import Severity, Sink, did_you_mean
from mpc.core.span import Span
from mpc.ir.naming import LINK_SUFFIX, SCOPES, NameRule, bad_pattern, edit_name, takes_link_suffix
from mpc.ir.ops import (
    ROOT,
    Attach,
    EditNames,
    LoadModel,
    Mirror,
    Op,
    RemoveBeyond,
    SetRobotName,
    TakeLeaf,
)
from mpc.ir.program import (
    CommandExport,
    Export,
    Input,
    JointLimitsExport,
    MjcfExport,
    PdfExport,
    Program,
    RepoRef,
    RosPackageExport,
    SdfExport,
    SubmodelExport,
    UrdfExport,
)
from mpc.ir.robot import Limit, Pose

# Sections of the model that later versions lower; named here so that nothing is ignored.
LATER_SECTIONS = ("swing_my_robot",)


def resolve_file(written: str, base_dir: Path, resolver: PackageResolver) -> Path:
    """A file named in a definition: `package://…`, absolute, or relative to its folder."""
    if written.startswith("package://"):
        source = resolver.resolve(written, base_dir)
        if source.path is not None:
            return source.path
    return (base_dir / written).resolve()


class Lowering:
    def __init__(self, ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver,
                 later: Severity) -> None:
        self.model, self.base_dir, self.sink = ast.model, base_dir, sink
        self.resolver, self.later = resolver, later
        self.ops: list[Op] = []
        self.rules: dict[str, tuple[NameRule, ...]] = {}
        self.link_suffix: dict[str, str] = {}  # append_link_suffix of each part
        self.smurf = SmurfLowering(ast.model, sink)

    def not_yet(self, span: Span, what: str) -> None:
        message = f"{what} is not supported yet"
        if self.later is Severity.ERROR:
            self.sink.error(span, "E0202", message)
        else:
            self.sink.warning(span, "W0202", message + " (checked, but `mpc compile` will refuse it)")

    # -- values ----------------------------------------------------------------------------

    def num(self, node: Node, key: str, what: str) -> float | None:
        value = getattr(node, key)
        return None if value is None else evaluate(value, node.value_span(key), self.sink, what=what)

    def num_value(self, value: object, span: Span, what: str) -> float | None:
        return evaluate(value, span, self.sink, what=what)

    @staticmethod
    def item_span(node: Node, key: str, i: int) -> Span:
        return _item_span(node, key, i)

    @staticmethod
    def pair_span(node: Node, key: str, a: str, b: str) -> Span:
        """The span of `b` in `key: {a: [..., b, ...]}` (or `{a: b}`)."""
        assert node._doc is not None
        path = (*node._path, key, a)
        value = node._doc.data_at(path)
        if isinstance(value, list) and b in value:
            return node._doc.value_span((*path, value.index(b)))
        return node._doc.value_span(path)

    def vec(self, node: Node, key: str, what: str) -> tuple[float, ...] | None:
        values = getattr(node, key)
        if values is None:
            return None
        out = [evaluate(v, _item_span(node, key, i), self.sink, what=f"{what}[{i}]")
               for i, v in enumerate(values)]
        return None if None in out else tuple(out)  # type: ignore[return-value]

    # -- inputs ----------------------------------------------------------------------------

    def folder_of(self, node: Node, key: str) -> Path:
        """The folder of the file that wrote `key` (a defaults file, or the definition)."""
        file = node.value_span(key).file
        return Path(file).resolve().parent if file else self.base_dir

    def inputs(self) -> dict[str, Input]:
        out = {}
        for name, entry in self.model.input_models.items():
            xacro_args = self.xacro_args(entry)
            if entry.basefile is not None:
                folder = self.folder_of(entry, "basefile")
                path: Path | None = resolve_file(entry.basefile, folder, self.resolver)
                source = self.resolver.resolve(entry.basefile, folder)
                if entry.basefile.startswith("package://") and source.path is None:
                    self.sink.error(entry.value_span("basefile"), "E0601",
                                    f"basefile '{entry.basefile}' of input model '{name}' cannot be "
                                    f"found: {source.unresolved}",
                                    hint="map the package with --package NAME=DIR or ROS_PACKAGE_PATH")
                    path = None
                out[name] = Input(name=name, kind="basefile", span=entry.value_span("basefile"),
                                  path=path, is_human=entry.is_human, xacro_args=xacro_args)
            elif entry.derived_base is not None:
                out[name] = Input(name=name, kind="derived_base", span=entry.value_span("derived_base"),
                                  path=(self.folder_of(entry, "derived_base") / entry.derived_base).resolve(),
                                  is_human=entry.is_human,
                                  smurf_data=self.model.inherit_smurf_properties)
            elif entry.repo is not None:
                r = entry.repo
                out[name] = Input(name=name, kind="repo", path=None, span=entry.value_span("repo"),
                                  is_human=entry.is_human, xacro_args=xacro_args,
                                  repo=RepoRef(git=r.git, commit=r.commit, branch=r.branch,
                                               model_in_repo=r.model_in_repo,
                                               submechanisms_in_repo=r.submechanisms_in_repo))
        return out

    def xacro_args(self, entry: Any) -> tuple[tuple[str, str], ...]:
        """The input's `xacro_args` as text (xacro's arguments are strings); a warning when its
        model file is no xacro, which ignores them."""
        if entry.xacro_args is None:
            return ()
        model = entry.basefile or (entry.repo.model_in_repo if entry.repo is not None else "")
        if not model.endswith(".xacro"):
            self.sink.warning(entry.key_span("xacro_args"), "W0622", f"xacro_args apply to a .xacro model "
                              f"file; '{model}' is none, so they are ignored")
            return ()
        text = {True: "true", False: "false"}
        out = []
        for key, value in sorted(entry.xacro_args.items()):
            if not isinstance(value, str | int | float | bool):
                self.sink.error(entry.value_span("xacro_args"), "E0240", f"xacro argument '{key}' is a "
                                "string, a number or a boolean (xacro's arguments are text)")
                continue
            out.append((key, text[value] if isinstance(value, bool) else str(value)))
        return tuple(out)

    # -- assembly --------------------------------------------------------------------------

    def name_rules(self, editing: NameEditing) -> tuple[NameRule, ...]:
        rules = []
        for scope in SCOPES:
            key = "" if scope == "all" else f"{scope}_"
            prefix, suffix = getattr(editing, f"{key}prefix"), getattr(editing, f"{key}suffix")
            replacements = getattr(editing, f"{key}replacements") or []
            pairs = []
            for i, item in enumerate(replacements):
                for pattern, replacement in item.items():
                    problem = bad_pattern(pattern)
                    if problem:
                        self.sink.error(_item_span(editing, f"{key}replacements", i), "E0305",
                                        f"'{pattern}' is not a regular expression: {problem}")
                        continue
                    pairs.append((pattern, str(replacement)))
            if prefix or suffix or pairs:
                rules.append(NameRule(scope=scope, prefix=prefix or "", suffix=suffix or "",
                                      replacements=tuple(pairs)))
        return tuple(rules)

    def part(self, node: AssemblyEntry, part: str, inputs: dict[str, Input]) -> None:
        if node.model not in inputs:
            self.sink.error(node.value_span("model"), "E0301",
                            f"model '{node.model}' in {node.SECTION} is not one of the input models "
                            f"({', '.join(sorted(inputs))}){did_you_mean(node.model, set(inputs))}")
            return
        self.ops.append(LoadModel(span=node.value_span("model"), part=part, input=node.model))
        rules: tuple[NameRule, ...] = ()
        editing = node.name_editing
        if editing is not None:
            rules = self.name_rules(editing)
            if rules or editing.joint_equals_link_name or editing.append_link_suffix:
                self.ops.append(EditNames(span=editing.span, part=part, rules=rules,
                                          joint_equals_link_name=editing.joint_equals_link_name,
                                          append_link_suffix=editing.append_link_suffix or ""))
            if editing.joint_equals_link_name:
                for key in ("joint_prefix", "joint_suffix", "joint_replacements"):
                    if getattr(editing, key):
                        self.sink.warning(editing.key_span(key), "W0550", f"'{key}' has no effect: "
                                          "joint_equals_link_name names every joint after its child link",
                                          hint="edit the link names instead; the joints follow them")
        self.rules[part] = rules
        self.link_suffix[part] = (editing.append_link_suffix or "") if editing is not None else ""
        if node.remove_beyond is not None:
            written_as_list = isinstance(node._doc.data_at((*node._path, "remove_beyond")), list)  # type: ignore[union-attr]
            spans = {f"links/{i}": _item_span(node, "remove_beyond", i) if written_as_list
                     else node.value_span("remove_beyond") for i in range(len(node.remove_beyond))}
            self.ops.append(RemoveBeyond(span=node.value_span("remove_beyond"), part=part, spans=spans,
                                         links=tuple(node.remove_beyond)))
        if node.take_leaf is not None:
            self.ops.append(TakeLeaf(span=node.value_span("take_leaf"), part=part, link=node.take_leaf))
        if node.mirror is not None:
            m = node.mirror
            plane = self.vec(m, "plane", "mirror plane")
            pairs = []
            for i, item in enumerate(m.name_replacements or []):
                for pattern, replacement in item.items():
                    problem = bad_pattern(pattern)
                    if problem:
                        self.sink.error(_item_span(m, "name_replacements", i), "E0305",
                                        f"'{pattern}' is not a regular expression: {problem}")
                    else:
                        pairs.append((pattern, str(replacement)))
            self.ops.append(Mirror(span=m.span, part=part, plane=plane or (0.0, 1.0, 0.0),
                                   flip_axis=m.flip_axis, exclude_meshes=tuple(m.exclude_meshes),
                                   name_replacements=tuple(pairs)))
        for i, child in enumerate(node.children):
            child_part = f"{part}/{i}"
            self.part(child, child_part, inputs)
            if child_part in self.rules:
                self.attach(child, part, child_part)

    def attach(self, child: AssembleChild, part: str, child_part: str) -> None:
        j: AttachJoint = child.joint
        what = f"joint of '{child.model}'"
        # Names in `joint:` are written as they are before each model's name editing.
        parent = self.edited_link(j.parent, part)
        child_link = self.edited_link(j.child, child_part) if j.child else None
        suffixed = tuple(field for field, p in (("parent", part), ("child_link", child_part))
                         if self.link_suffix[p] == "NAME_DUPLICATES")
        r2r = None
        if j.r2r_transform is not None:
            rows = [[evaluate(v, j.value_span("r2r_transform"), self.sink, what=f"{what} r2r_transform")
                     for v in row] for row in j.r2r_transform]
            if any(v is None for row in rows for v in row):
                return
            r2r = tuple(tuple(row) for row in rows)  # type: ignore[arg-type]
            if j.xyz is not None or j.rpy is not None:
                self.sink.error(j.key_span("r2r_transform"), "E0306",
                                f"{what}: give either r2r_transform or xyz/rpy, not both")
        xyz = self.vec(j, "xyz", f"{what} xyz") or (0.0, 0.0, 0.0)
        rpy = self.vec(j, "rpy", f"{what} rpy") or (0.0, 0.0, 0.0)
        limit = None
        values = {k: self.num(j, k, f"{what} {k}") for k in ("min", "max", "eff", "vel")}
        if any(v is not None for v in values.values()):
            limit = Limit(lower=values["min"], upper=values["max"], effort=values["eff"],
                          velocity=values["vel"])
        missing = [k for k in ("eff", "vel") if values[k] is None and k not in j.given]
        if j.type in ("revolute", "prismatic") and missing:
            name = j.name or (f"{parent}2{child_link}" if child_link else None)
            joint = f"joint '{name}' attaching '{child.model}'" if name else \
                f"the joint attaching '{child.model}' to '{j.parent}'"
            self.sink.error(j.key_span("type"), "E0307",
                            f"{joint} is {j.type} but has no {' and '.join(f'{k!r}' for k in missing)}"
                            "; URDF needs both 'eff' and 'vel' (Phobos silently used 0)")
        spans = {"parent": j.value_span("parent"), "child_link": j.value_span("child"),
                 "name": j.value_span("name")}
        self.ops.append(Attach(
            span=j.span, part=part, spans=spans, child=child_part, parent=parent,
            child_link=child_link, name=j.name, type=j.type,
            parent_written=j.parent if parent != j.parent else "",
            child_written=j.child if j.child and child_link != j.child else "",
            origin=Pose(xyz, rpy), r2r=r2r,  # type: ignore[arg-type]
            axis=self.vec(j, "axis", f"{what} axis"), limit=limit,  # type: ignore[arg-type]
            suffixed=suffixed,
        ))

    def edited_link(self, written: str, part: str) -> str:
        """A link name as written in `joint:`, after its part's name editing; NAME_DUPLICATES's
        suffix depends on the tree: Attach.resolved adds it."""
        name = edit_name(written, "link", self.rules[part])
        if self.link_suffix[part] == "ALWAYS" and takes_link_suffix(name, "ALWAYS", None):
            name += LINK_SUFFIX
        return name

    # -- the rest --------------------------------------------------------------------------

    def mesh_ops(self) -> None:
        """`apply_scale` and `reduce_meshes`, after every edit (they act on the final meshes)."""
        m = self.model
        if not m.apply_scale and m.reduce_meshes is None:
            return
        from mpc.ir.ops.meshes import ApplyScale, ReduceMeshes  # imported only for a definition that asks

        if m.apply_scale:
            self.ops.append(ApplyScale(span=m.key_span("apply_scale")))
        if m.reduce_meshes is not None:
            value = self.num(m, "reduce_meshes", "reduce_meshes")
            if value is None:
                return
            if 0 < value < 1:
                self.ops.append(ReduceMeshes(span=m.value_span("reduce_meshes"), ratio=value))
            elif value >= 4 and float(value).is_integer():
                self.ops.append(ReduceMeshes(span=m.value_span("reduce_meshes"), faces=int(value)))
            else:
                self.sink.error(m.value_span("reduce_meshes"), "E0203",
                                "'reduce_meshes' is a ratio of faces to keep (between 0 and 1) or a "
                                f"number of faces (4 or more), got {value:g}")

    def entries(self) -> list[Any]:
        """The model's export entries: `export_config` (inherited through `defaults` or the
        pipeline's `default_export_config`, or none: the default URDF), then the
        `append_export_config` entries. A new list each time: appending never changes the
        list it extends (Phobos appended in place, to every later model's default too)."""
        return [*(self.model.export_config or ()), *self.model.append_export_config]

    def exports(self) -> tuple[Export, ...]:
        out: list[Export] = []
        if self.model.export_config is None:
            out.append(UrdfExport(mesh_format="input_type", span=self.model.span))
        written: dict[str, Export] = {}
        for entry in self.entries():
            if entry.type == "submodel":
                out.extend(self.submodel(entry, written))
            else:
                out.extend(self.export(entry, written, self.model.robotname))
        # A joint_limits entry that lists a submodel's joints needs that submodel cut first.
        out = [e for e in out if not _lists_a_submodel(e)] + [e for e in out if _lists_a_submodel(e)]
        out.extend(self.smurf.exports(out))
        out.extend(self.commands())
        # A file with package:// paths (ros_pathes, or its copy) makes the output a ROS package.
        package = next((e.ros_package or e.copy_package for e in out if isinstance(e, UrdfExport | SdfExport)
                        and (e.ros_package or e.copy_package)), None)
        if package is not None:
            out.append(self.ros_package(package))
        return tuple(out)

    def export(self, entry: Any, written: dict[str, Export], robotname: str,
               submodel: str = "", inherited: bool = False) -> list[Export]:
        """One export_config entry; `submodel` names the submodel it writes (in submodels/<name>/,
        where its meshes are too: its `package://` paths point there)."""
        if entry.type == "kccd":
            from mpc.compiler.lower_kccd import lower_kccd

            if not inherited:
                return lower_kccd(self, entry, written, submodel)
            sink, self.sink = self.sink, Sink()  # the model's own use of the entry reported
            try:
                lowered = lower_kccd(self, entry, written, submodel)
                return [] if self.sink.has_errors() else lowered
            finally:
                self.sink = sink
        if entry.type == "render":
            from mpc.compiler.lower_render import lower_render

            target = f"{'submodels/' + submodel + '/' if submodel else ''}render/"
            if target in written:
                if not inherited:
                    self.sink.error(entry.span, "E0576", f"two render exports would write {target}",
                                    notes=((written[target].span, "the other export"),))
                return []
            render = lower_render(entry, self.sink if not inherited else Sink(), submodel)
            if render is None:
                return []
            written[target] = render
            return [render]
        if entry.type in ("pdf", "joint_limits"):
            export = self.simple_export(entry, inherited)
            return [] if export is None else [replace(export, submodel=submodel)]
        if entry.type == "smurf":
            self.smurf.entry(entry, submodel)
            return []
        if entry.type not in BUILT_EXPORTS:
            self.not_yet(entry.value_span("type"), f"export type '{entry.type}'"
                         + (" in a submodel" if submodel and entry.type == "submodel" else ""))
            return []
        if entry.type == "mjcf" and not inherited:  # the model's own use of the entry reported
            self.no_package_paths(entry)
        filename = (entry.filename or robotname) + entry.filename_suffix
        target = f"{'submodels/' + submodel + '/' if submodel else ''}{entry.type}/{filename}"
        if target in written:
            self.sink.error(entry.span, "E0503", f"two {entry.type} exports would write {target} "
                            "(Phobos silently let the last one win); give one a filename_suffix",
                            notes=((written[target].span, "the other export"),))
            return []
        mesh_format = entry.mesh_format
        if entry.type == "mjcf" and mesh_format == "input_type":
            mesh_format = "obj"  # MuJoCo reads no DAE, and OBJ has no 200k-face limit
        export = BUILT_EXPORTS[entry.type](mesh_format=mesh_format, span=entry.span,
                                           add_floating_base=entry.add_floating_base, submodel=submodel,
                                           filename=filename if filename != (submodel or robotname) else "")
        package = self.model.ros_pkg_name or self.model.modelname
        if entry.type in ("urdf", "sdf"):
            export = replace(export, ros_package=package if entry.ros_pathes else None,
                             copy_package=package if entry.copy_with_other_pathes else "")
        export = replace(export, correct_inertials=entry.correct_inertials)
        if entry.float_fmt_dict:
            export = replace(export, float_formats=self.float_formats(entry))
        if entry.type == "sdf":
            export = replace(export, version=entry.version, include_cut_joints=entry.include_cut_joints)
        elif entry.include_cut_joints:
            self.sink.error(entry.key_span("include_cut_joints"), "E0313", "'include_cut_joints' has "
                            f"no meaning in a {entry.type} export: "
                            + ("URDF cannot hold loops" if entry.type == "urdf"
                               else "MJCF always closes loops with equality constraints"))
        extra = entry.additional_meshes
        export = replace(export, enforce_zero=entry.enforce_zero,
                         additional_meshes=tuple([extra] if isinstance(extra, str) else extra or ()))
        export = self.smurf.link(entry, export, submodel)
        written[target] = export
        return [export]

    def no_package_paths(self, entry: Any) -> None:
        """`ros_pathes` and `copy_with_other_pathes` on an mjcf entry: MuJoCo cannot read them."""
        for key in ("ros_pathes", "copy_with_other_pathes"):
            if getattr(entry, key):
                self.sink.error(entry.key_span(key), "E0550", f"'{key}' writes package:// mesh paths, "
                                "which MuJoCo cannot resolve: it reads mesh files relative to the MJCF "
                                "file (or its meshdir), and knows no ROS packages",
                                hint="leave it out: the MJCF's relative paths work wherever the output "
                                "folder is; a urdf or sdf entry can have package paths")

    def float_formats(self, entry: Any) -> tuple[tuple[str, str], ...]:
        """`float_fmt_dict` of a urdf, sdf or mjcf entry, checked (backends/float_formats.py); sorted."""
        from mpc.ir.float_format_keys import DEFAULT, KEYS, bad_format

        keys = KEYS[entry.type]
        out = []
        for key, fmt in sorted(entry.float_fmt_dict.items()):
            path = (*entry._path, "float_fmt_dict", key)
            span = entry._doc.value_span(path)
            if key != DEFAULT and key not in keys:
                what = {"urdf": "attribute of a URDF", "sdf": "element of an SDF",
                        "mjcf": "attribute of an MJCF"}[entry.type]
                self.sink.error(entry._doc.keys.get(path, span), "E0530",
                                f"float_fmt_dict: '{key}' is no number {what} file"
                                f"{did_you_mean(key, set(keys) | {DEFAULT})}",
                                hint="'default' formats every number; the others are "
                                + ", ".join(sorted(keys)))
            elif bad_format(fmt):
                self.sink.error(span, "E0530", f"float_fmt_dict: '{fmt}' is not a format of one number; "
                                "write it as printf does, e.g. '%.6f', '%.8g' or '%e'")
            else:
                out.append((key, fmt))
        return tuple(out)

    def submodel(self, entry: Any, written: dict[str, Export]) -> list[Export]:
        """A `submodel` entry: the part of the robot it cuts out, then its exports (its own
        export_config, or the model's without submodels)."""
        for key, default in _SUBMODEL_LATER.items():
            if getattr(entry, key) != default:
                self.not_yet(entry.key_span(key), f"submodel option '{key}'")
        if entry.only_urdf:
            self.sink.warning(entry.key_span("only_urdf"), "W0523", "'only_urdf' has no effect (Phobos "
                              "stores it and never reads it)",
                              hint="give the submodel an export_config with only urdf entries")
        cut = SubmodelExport(span=entry.span, name=entry.name, start=entry.start or "",
                             stop=tuple([entry.stop] if isinstance(entry.stop, str) else entry.stop or ()),
                             include_unstopped_branches=entry.include_unstopped_branches,
                             add_floating_base=entry.add_floating_base,
                             remove_joints=_strings(entry.remove_joints), remove_fixed=entry.remove_fixed,
                             abstract_model=entry.abstract_model, no_submechanisms=entry.no_submechanisms,
                             name_replacements=tuple(entry.name_replacements.items()))
        for key, patterns in (("remove_joints", cut.remove_joints),
                              ("name_replacements", entry.name_replacements)):
            for pattern in patterns:
                problem = bad_pattern(pattern)
                if problem:
                    self.sink.error(entry.value_span(key), "E0305",
                                    f"'{pattern}' is not a regular expression: {problem}")
        moves = {}
        for joint, pair in entry.move_joint_axis_to_intersection.items():
            if len(pair) != 2:
                span = entry._doc.value_span((*entry._path, "move_joint_axis_to_intersection", joint))
                count = f"{len(pair)} joint{'' if len(pair) == 1 else 's'}"
                self.sink.error(span, "E0526", f"move_joint_axis_to_intersection of '{joint}' names "
                                f"{count}; it takes the two whose axes meet")
            moves[joint] = tuple(pair)
        cut = replace(cut, move_joint_axis_to_intersection=moves)
        folder = f"submodels/{entry.name}"
        if folder in written:
            self.sink.error(entry.value_span("name"), "E0503", f"two submodels would write {folder}",
                            notes=((written[folder].span, "the other submodel"),))
            return []
        written[folder] = cut
        out: list[Export] = [cut]
        nested = entry.export_config
        if nested is None:
            nested = [e for e in self.entries() if e.type != "submodel"]
            if self.model.export_config is None:
                out.append(UrdfExport(mesh_format="input_type", span=entry.span, submodel=entry.name,
                                      filename=entry.filename or ""))
        for inner in nested:
            out.extend(self.export(inner, written, entry.filename or entry.name, submodel=entry.name,
                                   inherited=entry.export_config is None))
        return out

    def commands(self) -> list[CommandExport]:
        """The post_processing commands. A string without `shell: true` is split as a shell
        would split it (so Phobos's `cmd: "check_urdf urdf/x.urdf"` runs), but no shell runs."""
        out = []
        for entry in self.model.post_processing:
            if isinstance(entry.cmd, list):
                if entry.shell:
                    self.sink.error(entry.key_span("shell"), "E0313", "'shell: true' runs one string; "
                                    "this cmd is a list of arguments, which runs without a shell")
                    continue
                command = tuple(entry.cmd)
            elif entry.shell:
                command = (entry.cmd,)
            else:
                syntax = _SHELL_SYNTAX.search(entry.cmd)
                if syntax is not None and "shell" not in entry.given:
                    self.sink.error(entry.value_span("cmd"), "E0560", f"this command has shell syntax "
                                    f"(`{syntax.group().strip()}`) but runs without a shell, so it would be "
                                    "passed to the program as an argument (Phobos ran every command "
                                    "through a shell)", hint="add `shell: true` to run it through /bin/sh, "
                                    "or give `cmd` as a list of arguments")
                    continue
                try:
                    command = tuple(shlex.split(entry.cmd))
                except ValueError as error:
                    self.sink.error(entry.value_span("cmd"), "E0203", f"cannot split this command into "
                                    f"arguments: {error}", hint="write it as a list, or add shell: true")
                    continue
                if not command:
                    self.sink.error(entry.value_span("cmd"), "E0203", "the command is empty")
                    continue
            if entry.cwd is not None and Path(entry.cwd).is_absolute():
                self.sink.error(entry.value_span("cwd"), "E0203", "'cwd' is relative to the definition's "
                                "folder; an absolute path would tie the definition to one machine")
                continue
            out.append(CommandExport(span=entry.value_span("cmd"), command=command, shell=entry.shell,
                                     cwd=entry.cwd or "", executable=entry.executable or ""))
        return out

    def ros_package(self, package: str) -> RosPackageExport:
        """The ROS package files, for the package that `ros_pathes` exports refer to."""
        m = self.model
        if not _ROS_NAME.fullmatch(package):
            key = "ros_pkg_name" if m.ros_pkg_name else "modelname"
            self.sink.error(m.value_span(key), "E0507", f"'{package}' is not a ROS package name (REP 144: "
                            "lower-case letters, digits and '_', starting with a letter)",
                            hint="set ros_pkg_name" if key == "modelname" else None)
        version = m.version or "0.0.0"
        if not _ROS_VERSION.fullmatch(version):
            self.sink.error(m.value_span("version"), "E0507", f"version '{version}' is not "
                            "MAJOR.MINOR.PATCH, which package.xml needs (REP 149), e.g. '1.2.0'")
        return RosPackageExport(span=m.span, package=package, version=version,
                                description=m.description or "", license=m.license or "")

    def simple_export(self, entry: Any, inherited: bool = False) -> Export | None:
        """The pdf and joint_limits entries (no meshes, no kinematic options). An entry a
        submodel inherits reports nothing: the model's own use of it did."""
        if entry.type == "pdf":
            return PdfExport(span=entry.span)
        joints = tuple(entry.joints)
        from mpc.ir.program import JOINT_SELECTIONS as SELECTIONS

        # `joints: name` (a string, not a list) of a submodel lists that submodel's joints.
        submodels = {e.name for e in self.entries() if e.type == "submodel"}
        as_string = isinstance(entry._doc.data_at((*entry._path, "joints")), str)
        if len(joints) == 1 and as_string and joints[0] in submodels:
            return JointLimitsExport(span=entry.span, file_name=entry.file_name, joints_of=joints[0])
        if len(joints) == 1 and as_string and joints[0].isupper() and joints[0] not in SELECTIONS:
            if inherited:
                return None
            self.sink.error(entry.value_span("joints"), "E0524", f"joints: '{joints[0]}' is none of "
                            f"{', '.join(SELECTIONS)} and names no submodel of this export_config"
                            f"{did_you_mean(joints[0], set(SELECTIONS) | submodels)}")
            return None
        return JointLimitsExport(span=entry.span, joints=joints, file_name=entry.file_name)

    def program(self) -> Program:
        """The program, also after errors (values that failed are None), so that the names
        in it can still be checked; the errors stop the build later."""
        inputs = self.inputs()
        self.part(self.model.assemble, ROOT, inputs)
        self.ops.append(SetRobotName(span=self.model.value_span("robotname"), name=self.model.robotname))
        EditLowering(self).run()
        self.mesh_ops()
        for key in LATER_SECTIONS:
            value = getattr(self.model, key)
            if value:
                self.not_yet(self.model.key_span(key), f"'{key}'")
        if not self.model.inherit_smurf_properties and not any(
                i.kind == "derived_base" for i in inputs.values()):
            self.sink.warning(self.model.key_span("inherit_smurf_properties"), "W0531",
                              "'inherit_smurf_properties: false' has no effect: no input model is a "
                              "derived_base", hint="it drops the SMURF data of derived_base inputs")
        for name, entry in self.model.input_models.items():
            if entry.is_human:
                self.not_yet(entry.key_span("is_human"), f"'is_human' (input model '{name}')")
        exports = self.exports()
        test = None
        if self.model.test is not None:
            from mpc.compiler.lower_test import lower_test

            test = lower_test(self.model.test, self.base_dir, self.sink)
        return Program(robotname=self.model.robotname, modelname=self.model.modelname,
                       inputs=inputs, ops=tuple(self.ops), exports=exports, span=self.model.span,
                       test=test, deployment=lower_model_deployment(self.model, self.sink))


# Export types `mpc compile` writes; the others are reported as not supported yet.
_ROS_NAME = re.compile(r"[a-z][a-z0-9_]*")
# What a shell would read differently from a plain split into arguments: redirections, pipes,
# `;`, `&&`, `&`, `$` expansions, back quotes, subshells, globs, quotes, escapes, and `~`.
_SHELL_SYNTAX = re.compile(r"&&|\|\||[|;&<>$`()*?'\"\\]|\[.*\]|(?:^|\s)~")
_ROS_VERSION = re.compile(r"(0|[1-9][0-9]*)\.(0|[1-9][0-9]*)\.(0|[1-9][0-9]*)")
# Submodel options not built yet, with their defaults.
_SUBMODEL_LATER: dict[str, Any] = {
    "include_human_in_abstract": False, "remove_links": []}
BUILT_EXPORTS: dict[str, Any] = {"urdf": UrdfExport, "sdf": SdfExport, "mjcf": MjcfExport}



def _lists_a_submodel(export: Export) -> bool:
    return isinstance(export, JointLimitsExport) and bool(export.joints_of)


def _strings(value: str | list[str] | None) -> tuple[str, ...]:
    """A `OneOrMore` value as a tuple."""
    return (value,) if isinstance(value, str) else tuple(value or ())


def _item_span(node: Node, key: str, i: int) -> Span:
    assert node._doc is not None
    return node._doc.value_span((*node._path, key, i))


def lower(ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver,
          later: Severity = Severity.ERROR) -> Program | None:
    """The program of a validated definition file in `base_dir`; None after errors."""
    return Lowering(ast, base_dir, sink, resolver, later).program()

