"""AST → ir.Program: inputs resolved to files, ops in the order the language fixes.

Lowering reads no input model. It evaluates every number (compiler/expr.py), turns
name editing into rules, and emits, for each part of the assembly tree depth-first:
load, name editing, remove_beyond, take_leaf, mirror, then its children, then the
attach to its parent. Parts of the language that later versions will lower are
reported through `later` (an error for `compile`, a warning for `check`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mpc.backends.packages import PackageResolver
from mpc.compiler.diagnostics import Severity, Sink, did_you_mean
from mpc.compiler.expr import evaluate
from mpc.compiler.lower_edits import EditLowering
from mpc.compiler.schema import Definition
from mpc.compiler.schema.assembly import AssembleChild, AttachJoint, NameEditing, _Part
from mpc.compiler.schema.base import Node
from mpc.ir.naming import SCOPES, NameRule, bad_pattern, edit_name
from mpc.ir.ops import ROOT, Attach, EditNames, LoadModel, Mirror, Op, RemoveBeyond, SetRobotName, TakeLeaf
from mpc.ir.program import Input, Program, RepoRef, UrdfExport
from mpc.ir.robot import Limit, Pose
from mpc.ir.span import Span

# Sections of the model that later versions lower; named here so that nothing is ignored.
LATER_SECTIONS = ("post_processing", "test", "deployment", "append_export_config", "reduce_meshes",
                  "apply_scale", "swing_my_robot")


def resolve_file(written: str, base_dir: Path, resolver: PackageResolver) -> Path:
    """A file named in a definition: `package://…`, absolute, or relative to its folder."""
    if written.startswith("package://"):
        source = resolver.resolve(written, base_dir)
        if source.path is not None:
            return source.path
    return (base_dir / written).resolve()


class _Lowering:
    def __init__(self, ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver,
                 later: Severity) -> None:
        self.model, self.base_dir, self.sink = ast.model, base_dir, sink
        self.resolver, self.later = resolver, later
        self.ops: list[Op] = []
        self.rules: dict[str, tuple[NameRule, ...]] = {}

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

    def vec(self, node: Node, key: str, what: str) -> tuple[float, ...] | None:
        values = getattr(node, key)
        if values is None:
            return None
        out = [evaluate(v, _item_span(node, key, i), self.sink, what=f"{what}[{i}]")
               for i, v in enumerate(values)]
        return None if None in out else tuple(out)  # type: ignore[return-value]

    # -- inputs ----------------------------------------------------------------------------

    def inputs(self) -> dict[str, Input]:
        out = {}
        for name, entry in self.model.input_models.items():
            if entry.basefile is not None:
                path: Path | None = resolve_file(entry.basefile, self.base_dir, self.resolver)
                source = self.resolver.resolve(entry.basefile, self.base_dir)
                if entry.basefile.startswith("package://") and source.path is None:
                    self.sink.error(entry.value_span("basefile"), "E0601",
                                    f"basefile '{entry.basefile}' of input model '{name}' cannot be "
                                    f"found: {source.unresolved}",
                                    hint="map the package with --package NAME=DIR or ROS_PACKAGE_PATH")
                    path = None
                out[name] = Input(name=name, kind="basefile", span=entry.value_span("basefile"),
                                  path=path, is_human=entry.is_human)
            elif entry.derived_base is not None:
                out[name] = Input(name=name, kind="derived_base", span=entry.value_span("derived_base"),
                                  path=(self.base_dir / entry.derived_base).resolve(),
                                  is_human=entry.is_human)
            elif entry.repo is not None:
                r = entry.repo
                out[name] = Input(name=name, kind="repo", path=None, span=entry.value_span("repo"),
                                  is_human=entry.is_human,
                                  repo=RepoRef(git=r.git, commit=r.commit, branch=r.branch,
                                               model_in_repo=r.model_in_repo,
                                               submechanisms_in_repo=r.submechanisms_in_repo))
        return out

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
        for flag in ("joint_equals_link_name", "append_link_suffix"):
            if getattr(editing, flag):
                self.not_yet(editing.key_span(flag), f"name_editing '{flag}'")
        return tuple(rules)

    def part(self, node: _Part, part: str, inputs: dict[str, Input]) -> None:
        if node.model not in inputs:
            self.sink.error(node.value_span("model"), "E0301",
                            f"model '{node.model}' in {node.SECTION} is not one of the input models "
                            f"({', '.join(sorted(inputs))}){did_you_mean(node.model, set(inputs))}")
            return
        self.ops.append(LoadModel(span=node.value_span("model"), part=part, input=node.model))
        rules: tuple[NameRule, ...] = ()
        if node.name_editing is not None:
            rules = self.name_rules(node.name_editing)
            if rules:
                self.ops.append(EditNames(span=node.name_editing.span, part=part, rules=rules))
        self.rules[part] = rules
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
        parent = edit_name(j.parent, "link", self.rules[part])
        child_link = edit_name(j.child, "link", self.rules[child_part]) if j.child else None
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
        if j.type in ("revolute", "prismatic") and (limit is None or limit.effort is None
                                                    or limit.velocity is None):
            self.sink.error(j.key_span("type"), "E0307",
                            f"{what} is {j.type} but has no 'eff' and 'vel'; URDF needs both "
                            "(Phobos silently used 0)")
        spans = {"parent": j.value_span("parent"), "child_link": j.value_span("child"),
                 "name": j.value_span("name")}
        self.ops.append(Attach(
            span=j.span, part=part, spans=spans, child=child_part, parent=parent,
            child_link=child_link, name=j.name, type=j.type,
            parent_written=j.parent if parent != j.parent else "",
            child_written=j.child if j.child and child_link != j.child else "",
            origin=Pose(xyz, rpy), r2r=r2r,  # type: ignore[arg-type]
            axis=self.vec(j, "axis", f"{what} axis"), limit=limit,  # type: ignore[arg-type]
        ))

    # -- the rest --------------------------------------------------------------------------

    def exports(self) -> tuple[UrdfExport, ...]:
        if self.model.export_config is None:
            return (UrdfExport(mesh_format="input_type", span=self.model.span),)
        out = []
        for entry in self.model.export_config:
            if entry.type != "urdf":
                self.not_yet(entry.value_span("type"), f"export type '{entry.type}'")
                continue
            for key, default in _URDF_DEFAULTS.items():
                if getattr(entry, key) != default:
                    self.not_yet(entry.key_span(key), f"urdf export option '{key}'")
            out.append(UrdfExport(mesh_format=entry.mesh_format, span=entry.span))
        return tuple(out)

    def program(self) -> Program:
        """The program, also after errors (values that failed are None), so that the names
        in it can still be checked; the errors stop the build later."""
        inputs = self.inputs()
        self.part(self.model.assemble, ROOT, inputs)
        self.ops.append(SetRobotName(span=self.model.value_span("robotname"), name=self.model.robotname))
        EditLowering(self).run()
        for key in LATER_SECTIONS:
            value = getattr(self.model, key)
            if value:
                self.not_yet(self.model.key_span(key), f"'{key}'")
        exports = self.exports()
        return Program(robotname=self.model.robotname, modelname=self.model.modelname,
                       inputs=inputs, ops=tuple(self.ops), exports=exports, span=self.model.span)


_URDF_DEFAULTS: dict[str, Any] = {
    "additional_meshes": None, "link_in_smurf": False, "include_cut_joints": False,
    "filename_suffix": "", "filename": None, "ros_pathes": False, "copy_with_other_pathes": False,
    "enforce_zero": False, "add_floating_base": False, "correct_inertials": False,
    "float_fmt_dict": None,
}


def _item_span(node: Node, key: str, i: int) -> Span:
    assert node._doc is not None
    return node._doc.value_span((*node._path, key, i))


def lower(ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver,
          later: Severity = Severity.ERROR) -> Program | None:
    """The program of a validated definition file in `base_dir`; None after errors."""
    return _Lowering(ast, base_dir, sink, resolver, later).program()

