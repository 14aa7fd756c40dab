"""`export_config` and `post_processing` (AST) → ir Exports: one per file or folder written.

Input: the model's export entries (`export_config`, or the default URDF, then
`append_export_config`), each submodel's entries, the post_processing commands. Output: the
exports in the order they are written; a joint_limits export that lists a submodel's joints
after that submodel, the SMURFs (compiler/lower_smurf.py) after the files they link, then the
commands and the ROS package. It reads no model: names are checked when the files are written.
"""

from __future__ import annotations

import re
import shlex
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from mpc.backends.formats import FORMATS, Format
from mpc.compiler.lower_context import LowerContext, strings
from mpc.compiler.lower_joint_limits import lower_joint_limits
from mpc.compiler.lower_smurf import SmurfLowering
from mpc.compiler.schema import exports as schema
from mpc.compiler.schema.base import Node
from mpc.core.diagnostics import did_you_mean
from mpc.core.record import record
from mpc.ir.program import (
    CommandExport,
    Export,
    JointLimitsExport,
    PdfExport,
    RosPackageExport,
    SdfExport,
    SubmodelExport,
    UrdfExport,
    UsdExport,
)


def lower_exports(ctx: LowerContext) -> tuple[Export, ...]:
    """The exports of the definition (see the module docstring)."""
    return _Exports(ctx).exports()


class _Exports:
    """One definition's exports as they are lowered: `written` maps each output path to the
    export that writes it (two writing one path is an error); `smurf` collects what the
    entries say about the SMURFs."""

    def __init__(self, ctx: LowerContext) -> None:
        self.ctx = ctx
        self.written: dict[str, Export] = {}
        self.smurf = SmurfLowering(ctx.model, ctx.sink)

    def entries(self) -> list[Any]:
        """The model's export entries: `export_config` (inherited through `defaults` or the
        pipeline's `default_export_config`, or none: the default URDF), then the
        `append_export_config` entries. A new list each time: appending never changes the
        list it extends (Phobos appended in place, to every later model's default too)."""
        return [*(self.ctx.model.export_config or ()), *self.ctx.model.append_export_config]

    def exports(self) -> tuple[Export, ...]:
        out: list[Export] = []
        if self.ctx.model.export_config is None:
            out.append(UrdfExport(mesh_format="input_type", span=self.ctx.model.span))
        for entry in self.entries():
            if entry.type == "submodel":
                out.extend(self.submodel(entry))
            else:
                out.extend(self.export(entry, self.ctx.model.robotname))
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

    def export(self, entry: Any, robotname: str,
               submodel: str = "", inherited: bool = False) -> list[Export]:
        """One export_config entry; `submodel` names the submodel it writes (in submodels/<name>/,
        where its meshes are too: its `package://` paths point there). Its lowering is its
        type's in `LOWERING`."""
        lowering = LOWERING.get(entry.type)
        if lowering is None:
            self.ctx.not_yet(entry.value_span("type"), f"export type '{entry.type}'"
                             + (" in a submodel" if submodel and entry.type == "submodel" else ""))
            return []
        return lowering.lower(self, entry, robotname, submodel, inherited)

    def kccd(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        from mpc.compiler.lower_kccd import lower_kccd

        if not inherited:
            return lower_kccd(self.ctx, entry, self.written, submodel)
        quiet = self.ctx.quiet()  # the model's own use of the entry reported
        lowered = lower_kccd(quiet, entry, self.written, submodel)
        return [] if quiet.sink.has_errors() else lowered

    def render(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        from mpc.compiler.lower_render import lower_render

        target = f"{'submodels/' + submodel + '/' if submodel else ''}render/"
        if target in self.written:
            if not inherited:
                self.ctx.sink.error(entry.span, "E0576", f"two render exports would write {target}",
                                    notes=((self.written[target].span, "the other export"),))
            return []
        render = lower_render(entry, (self.ctx.quiet() if inherited else self.ctx).sink, submodel)
        if render is None:
            return []
        self.written[target] = render
        return [render]

    def pdf(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        """A pdf entry: no meshes, no kinematic options."""
        return [PdfExport(span=entry.span, submodel=submodel)]

    def smurf_entry(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        self.smurf.entry(entry, submodel)
        return []

    def kinematic(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        """A urdf, sdf or mjcf entry: a model file and its meshes, as its format's descriptor
        (backends/formats.py) says."""
        fmt = FORMATS[entry.type]
        if not inherited:  # the model's own use of the entry reported
            self.no_effect(entry, fmt)
        filename = (entry.filename or robotname) + entry.filename_suffix
        target = f"{'submodels/' + submodel + '/' if submodel else ''}{entry.type}/{filename}"
        if target in self.written:
            self.ctx.sink.error(entry.span, "E0503", f"two {entry.type} exports would write {target} "
                                "(Phobos silently let the last one win); give one a filename_suffix",
                                notes=((self.written[target].span, "the other export"),))
            return []
        mesh_format = entry.mesh_format
        if mesh_format == "input_type" and fmt.meshes is not None and fmt.meshes.input_type:
            mesh_format = fmt.meshes.input_type  # MJCF: MuJoCo reads no DAE, and OBJ has no 200k-face limit
        assert fmt.record is not None
        export = fmt.record(mesh_format=mesh_format, span=entry.span,
                            add_floating_base=entry.add_floating_base, submodel=submodel,
                            filename=filename if filename != (submodel or robotname) else "")
        export = self.smurf.link(entry, self.options(entry, fmt, export), submodel)
        self.written[target] = export
        return [export]

    def usd(self, entry: Any, robotname: str, submodel: str, inherited: bool) -> list[Export]:
        """A usd entry: `usd/<filename>.usda` (and its payload folder), as kinematic files are
        named; two writing one file are E0503."""
        filename = (entry.filename or robotname) + entry.filename_suffix
        target = f"{'submodels/' + submodel + '/' if submodel else ''}usd/{filename}"
        if target in self.written:
            self.ctx.sink.error(entry.span, "E0503", f"two usd exports would write {target}; give one a "
                                "filename_suffix", notes=((self.written[target].span, "the other export"),))
            return []
        export = UsdExport(span=entry.span, layout=entry.layout, submodel=submodel,
                           add_floating_base=entry.add_floating_base,
                           correct_inertials=entry.correct_inertials,
                           filename=filename if filename != (submodel or robotname) else "")
        self.written[target] = export
        return [export]

    def no_effect(self, entry: Any, fmt: Format) -> None:
        """Report the keys of a urdf, sdf or mjcf entry that its format ignores or cannot honour."""
        if not fmt.package_paths:
            self.no_package_paths(entry)
        if entry.provide_primitives:
            self.ctx.sink.warning(entry.key_span("provide_primitives"), "W0260", "'provide_primitives' has "
                                  "no effect: Phobos's export reads it from no export entry (its default "
                                  "preset sets it on sdf), and mpc writes the collisions as they are",
                                  hint="collisions' `shape` with `apply_primitives: true` makes primitive "
                                  "collisions")

    def options(self, entry: Any, fmt: Format, export: Any) -> Any:
        """`export` with the options of its entry that its format takes."""
        package = self.ctx.model.ros_pkg_name or ros_name(self.ctx.model.modelname)
        if fmt.package_paths:
            export = replace(export, ros_package=package if entry.ros_pathes else None,
                             copy_package=package if entry.copy_with_other_pathes else "")
        export = replace(export, correct_inertials=entry.correct_inertials)
        if entry.float_fmt_dict:
            export = replace(export, float_formats=self.float_formats(entry))
        if not fmt.cut_joints:
            export = replace(export, version=entry.version, include_cut_joints=entry.include_cut_joints)
        elif entry.include_cut_joints:
            self.ctx.sink.error(entry.key_span("include_cut_joints"), "E0313", "'include_cut_joints' has "
                                f"no meaning in a {entry.type} export: {fmt.cut_joints}")
        if entry.type == "mjcf":
            export = replace(export, actuators=entry.actuators, scene=entry.scene)
        extra = entry.additional_meshes
        return replace(export, enforce_zero=entry.enforce_zero,
                       additional_meshes=tuple([extra] if isinstance(extra, str) else extra or ()))

    def no_package_paths(self, entry: Any) -> None:
        """`ros_pathes` and `copy_with_other_pathes` on an mjcf entry: MuJoCo cannot read them."""
        for key in ("ros_pathes", "copy_with_other_pathes"):
            if getattr(entry, key):
                self.ctx.sink.error(entry.key_span(key), "E0550", f"'{key}' writes package:// mesh paths, "
                                    "which MuJoCo cannot resolve: it reads mesh files relative to the MJCF "
                                    "file (or its meshdir), and knows no ROS packages",
                                    hint="leave it out: the MJCF's relative paths work wherever the output "
                                    "folder is; a urdf or sdf entry can have package paths")

    def float_formats(self, entry: Any) -> tuple[tuple[str, str], ...]:
        """`float_fmt_dict` of a urdf, sdf or mjcf entry, checked (backends/float_formats.py); sorted."""
        from mpc.ir.float_format_keys import DEFAULT, bad_format

        keys = FORMATS[entry.type].float_keys
        out = []
        for key, fmt in sorted(entry.float_fmt_dict.items()):
            span = entry.value_span("float_fmt_dict", key)
            if key != DEFAULT and key not in keys:
                what = FORMATS[entry.type].numbers
                self.ctx.sink.error(entry.key_span("float_fmt_dict", key), "E0530",
                                    f"float_fmt_dict: '{key}' is no number {what} file"
                                    f"{did_you_mean(key, set(keys) | {DEFAULT})}",
                                    hint="'default' formats every number; the others are "
                                    + ", ".join(sorted(keys)))
            elif bad_format(fmt):
                self.ctx.sink.error(span, "E0530", f"float_fmt_dict: '{fmt}' is not a format of one number; "
                                    "write it as printf does, e.g. '%.6f', '%.8g' or '%e'")
            else:
                out.append((key, fmt))
        return tuple(out)

    def submodel(self, entry: Any) -> list[Export]:
        """A `submodel` entry: the part of the robot it cuts out, then its exports (its own
        export_config, or the model's without submodels)."""
        for key, default in _SUBMODEL_LATER.items():
            if getattr(entry, key) != default:
                self.ctx.not_yet(entry.key_span(key), f"submodel option '{key}'")
        if entry.only_urdf:
            self.ctx.sink.warning(entry.key_span("only_urdf"), "W0523", "'only_urdf' has no effect (Phobos "
                                  "stores it and never reads it)",
                                  hint="give the submodel an export_config with only urdf entries")
        cut = SubmodelExport(span=entry.span, name=entry.name, start=entry.start or "",
                             stop=tuple([entry.stop] if isinstance(entry.stop, str) else entry.stop or ()),
                             include_unstopped_branches=entry.include_unstopped_branches,
                             add_floating_base=entry.add_floating_base,
                             remove_joints=strings(entry.remove_joints), remove_fixed=entry.remove_fixed,
                             abstract_model=entry.abstract_model, no_submechanisms=entry.no_submechanisms,
                             name_replacements=tuple(entry.name_replacements.items()))
        for key, patterns in (("remove_joints", cut.remove_joints),
                              ("name_replacements", entry.name_replacements)):
            self.ctx.patterns((pattern, entry.value_span(key)) for pattern in patterns)
        moves = {}
        for joint, pair in entry.move_joint_axis_to_intersection.items():
            if len(pair) != 2:
                span = entry.value_span("move_joint_axis_to_intersection", joint)
                count = f"{len(pair)} joint{'' if len(pair) == 1 else 's'}"
                self.ctx.sink.error(span, "E0526", f"move_joint_axis_to_intersection of '{joint}' names "
                                    f"{count}; it takes the two whose axes meet")
            moves[joint] = tuple(pair)
        cut = replace(cut, move_joint_axis_to_intersection=moves)
        folder = f"submodels/{entry.name}"
        if folder in self.written:
            self.ctx.sink.error(entry.value_span("name"), "E0503", f"two submodels would write {folder}",
                                notes=((self.written[folder].span, "the other submodel"),))
            return []
        self.written[folder] = cut
        out: list[Export] = [cut]
        nested = entry.export_config
        if nested is None:
            nested = [e for e in self.entries() if e.type != "submodel"]
            if self.ctx.model.export_config is None:
                out.append(UrdfExport(mesh_format="input_type", span=entry.span, submodel=entry.name,
                                      filename=entry.filename or ""))
        for inner in nested:
            out.extend(self.export(inner, entry.filename or entry.name, submodel=entry.name,
                                   inherited=entry.export_config is None))
        return out

    def commands(self) -> list[CommandExport]:
        """The post_processing commands. A string without `shell: true` is split as a shell
        would split it (so Phobos's `cmd: "check_urdf urdf/x.urdf"` runs), but no shell runs."""
        out = []
        for entry in self.ctx.model.post_processing:
            if isinstance(entry.cmd, list):
                if entry.shell:
                    self.ctx.sink.error(entry.key_span("shell"), "E0313", "'shell: true' runs one string; "
                                        "this cmd is a list of arguments, which runs without a shell")
                    continue
                command = tuple(entry.cmd)
            elif entry.shell:
                command = (entry.cmd,)
            else:
                syntax = _SHELL_SYNTAX.search(entry.cmd)
                if syntax is not None and "shell" not in entry.given:
                    self.ctx.sink.error(entry.value_span("cmd"), "E0560", "this command has shell "
                                        f"syntax (`{syntax.group().strip()}`) but runs without a shell, "
                                        "so it would be passed to the program as an argument (Phobos "
                                        "ran every command through a shell)",
                                        hint="add `shell: true` to run it through /bin/sh, "
                                        "or give `cmd` as a list of arguments")
                    continue
                try:
                    command = tuple(shlex.split(entry.cmd))
                except ValueError as error:
                    self.ctx.sink.error(entry.value_span("cmd"), "E0203", f"cannot split this command into "
                                        f"arguments: {error}", hint="write it as a list, or add shell: true")
                    continue
                if not command:
                    self.ctx.sink.error(entry.value_span("cmd"), "E0203", "the command is empty")
                    continue
            if entry.cwd is not None and Path(entry.cwd).is_absolute():
                self.ctx.sink.error(entry.value_span("cwd"), "E0203", "'cwd' is relative to the definition's "
                                    "folder; an absolute path would tie the definition to one machine")
                continue
            bad = [(i, n) for i, n in enumerate(entry.env) if not _VARIABLE.fullmatch(n)]
            for i, name in bad:
                listed = isinstance(entry.data_at("env"), list)
                where = entry.value_span("env", i) if listed else entry.value_span("env")
                self.ctx.sink.error(where, "E0541", f"'{name}' is not the name of an environment "
                                    "variable (letters, digits and '_', not a digit first)")
            if bad:
                continue
            out.append(CommandExport(span=entry.value_span("cmd"), command=command, shell=entry.shell,
                                     cwd=entry.cwd or "", executable=entry.executable or "",
                                     env=tuple(entry.env)))
        return out

    def ros_package(self, package: str) -> RosPackageExport:
        """The ROS package files, for the package that `ros_pathes` exports refer to."""
        m = self.ctx.model
        if m.ros_pkg_name and not _ROS_NAME.fullmatch(package):
            self.ctx.sink.error(m.value_span("ros_pkg_name"), "E0507",
                                f"'{package}' is not a ROS package name (REP 144: "
                                "lower-case letters, digits and '_', starting with a letter)")
        elif not m.ros_pkg_name and package != m.modelname:
            self.ctx.sink.warning(m.value_span("modelname"), "W0261",
                                  f"modelname '{m.modelname}' is not a ROS package name (REP 144: lower-case "
                                  "letters, digits and '_', starting with a letter); the ROS package that "
                                  f"ros_pathes makes is named '{package}' (Phobos keeps the modelname, "
                                  "which no ROS tool finds)",
                                  hint="set ros_pkg_name to choose the package's name")
        version = m.version or "0.0.0"
        if not _ROS_VERSION.fullmatch(version):
            self.ctx.sink.error(m.value_span("version"), "E0507", f"version '{version}' is not "
                                "MAJOR.MINOR.PATCH, which package.xml needs (REP 149), e.g. '1.2.0'")
        return RosPackageExport(span=m.span, package=package, version=version,
                                description=m.description or "", license=m.license or "")

    def submodel_names(self) -> set[str]:
        return {e.name for e in self.entries() if e.type == "submodel"}


Lower = Callable[[_Exports, Any, str, str, bool], list[Export]]


@record
class Lowering:
    """How the compiler takes an export type: its schema node (the `export_config` entry) and the
    function that lowers an entry (the exports, the entry, the robot's name, the submodel that
    writes it or "", whether a submodel inherits it) to IR exports. The format's other facts are
    its descriptor's (backends/formats.py)."""

    schema: type[Node]
    lower: Lower


# Each export type the compiler lowers; an entry of another type is reported as not supported
# yet. (`submodel` entries are lowered apart: they hold exports of their own.)
LOWERING: dict[str, Lowering] = {
    "urdf": Lowering(schema.UrdfExport, _Exports.kinematic),
    "sdf": Lowering(schema.SdfExport, _Exports.kinematic),
    "mjcf": Lowering(schema.MjcfExport, _Exports.kinematic),
    "usd": Lowering(schema.UsdExport, _Exports.usd),
    "smurf": Lowering(schema.SmurfExport, _Exports.smurf_entry),
    "pdf": Lowering(schema.PdfExport, _Exports.pdf),
    "render": Lowering(schema.RenderExport, _Exports.render),
    "joint_limits": Lowering(schema.JointLimitsExport, lambda exports, entry, robotname, submodel, inherited:
                             lower_joint_limits(exports.ctx, entry, exports.submodel_names(), submodel,
                                                inherited)),
    "kccd": Lowering(schema.KccdExport, _Exports.kccd),
}


_ROS_NAME = re.compile(r"[a-z][a-z0-9_]*")


def ros_name(modelname: str) -> str:
    """`modelname` as a ROS package name (REP 144): lower case, each run of other characters
    one '_', none at either end, `pkg_` before a first character that is no letter."""
    if _ROS_NAME.fullmatch(modelname):
        return modelname
    name = re.sub(r"[^a-z0-9]+", "_", modelname.lower()).strip("_") or "model"
    return name if name[0].isalpha() else f"pkg_{name}"
# What a shell would read differently from a plain split into arguments: redirections, pipes,
# `;`, `&&`, `&`, `$` expansions, back quotes, subshells, globs, quotes, escapes, and `~`.
_VARIABLE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_SHELL_SYNTAX = re.compile(r"&&|\|\||[|;&<>$`()*?'\"\\]|\[.*\]|(?:^|\s)~")
_ROS_VERSION = re.compile(r"(0|[1-9][0-9]*)\.(0|[1-9][0-9]*)\.(0|[1-9][0-9]*)")
# Submodel options not built yet, with their defaults.
_SUBMODEL_LATER: dict[str, Any] = {
    "include_human_in_abstract": False, "remove_links": []}


def _lists_a_submodel(export: Export) -> bool:
    return isinstance(export, JointLimitsExport) and bool(export.joints_of)

