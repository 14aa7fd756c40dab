"""Editing sections of the AST → ops, in the order the language fixes.

Each step below lowers one piece of one section and returns its ops; `EDIT_STEPS` declares
their order, which is the language's (Phobos's, §2.8): sections in the order of their phases
(ir/ops/base.py: Phase), and within a section —
- frames: new frames, make_root, `$default`, per-link edits, per-link name editing, `$name_editing`;
- joints: `$replace_joint_types`, cut joints, `$default`, `$backup`, per-joint edits, removals,
  per-joint name editing, `$name_editing`;
- collisions: name editing, then `$default` and per-entry edits, then bitmasks;
- visuals: name editing, then `$default` and per-entry edits.
It reads no model: the names it writes are checked by the passes (compiler/passes/check_names.py).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from mpc.compiler.lower_context import LowerContext, items_span, pair_span
from mpc.compiler.schema.annotations import MULTI_LINK_SENSORS, SINGLE_LINK_SENSORS, sensor_entries
from mpc.compiler.schema.base import Node
from mpc.compiler.schema.editing import FrameDef, JointDef, MotorDef
from mpc.core.files import input_problem, project_root, resolved
from mpc.ir import ops
from mpc.ir.ops import Op

if TYPE_CHECKING:
    from mpc.ir.ops import SetMotor
    from mpc.ir.ops.joints import JointValues

_LIMIT_KEYS = {"min": "lower", "max": "upper", "eff": "effort", "vel": "velocity", "friction": "friction",
               "damping": "damping", "spring_stiffness": "spring_stiffness",
               "spring_reference": "spring_reference"}

Step = Callable[[LowerContext], list[Op]]


def _spans(node: Node, *keys: str) -> dict[str, Any]:
    return {k: node.value_span(k) for k in keys}


def removal(ctx: LowerContext, d: Any, what: str) -> bool | tuple[str, ...]:
    """`remove`: true, or names and regular expressions (checked, E0305)."""
    if isinstance(d.remove, bool):
        return d.remove
    return tuple(ctx.patterns(((pattern, items_span(d, "remove", i)) for i, pattern in enumerate(d.remove)),
                              where=f" in {what} remove"))


def refuse(ctx: LowerContext, d: Node, where: str, keys: tuple[str, ...]) -> None:
    """Report keys that mean nothing in this place (instead of ignoring them)."""
    for key in keys:
        if key in d.given:
            ctx.sink.error(d.key_span(key), "E0313", f"'{key}' has no meaning in {where}")


def scoped_names(ctx: LowerContext, editing: Any, where: str, scope: str, only: tuple[str, ...] = ()) -> Op:
    """Name editing of one kind of name (of the names `only`, else of all): the keys of other
    kinds would do nothing, nor the flags of an assembly entry's name_editing, which rename by
    the tree."""
    flags = {"joint_equals_link_name", "append_link_suffix"}
    for key in sorted(editing.given & flags):
        ctx.sink.error(editing.key_span(key), "E0313", f"'{key}' has no meaning in {where}; "
                       "it is a key of an assemble entry's name_editing")
    for key in editing.given - flags:
        kind = key.split("_", 1)[0]
        if "_" in key and kind in ("link", "joint", "collision", "visual", "submechanism") \
                and kind != scope:
            ctx.sink.error(editing.key_span(key), "E0313", f"'{key}' has no meaning in {where}, "
                           f"which renames {scope}s only")
    if only:
        return ops.EditNames(span=editing.span, rules=ctx.name_rules(editing), kinds=(scope,), only=only)
    return ops.EditNames(span=editing.span, kinds=(scope,), rules=ctx.name_rules(editing))


# -- materials and frames -----------------------------------------------------------------

def materials(ctx: LowerContext) -> list[Op]:
    out: list[Op] = []
    for name, d in ctx.model.materials.items():
        colours = {k: ctx.vec(d, k, f"material '{name}' {k}") for k in
                   ("diffuse", "ambient", "specular", "emissive")}
        out.append(ops.EditMaterial(span=d.span, name=name, **colours, texture=d.texture,
                                    normal_texture=d.normalTexture,
                                    shininess=ctx.num(d, "shininess", f"material '{name}' shininess"),
                                    transparency=ctx.num(d, "transparency",
                                                         f"material '{name}' transparency"),
                                    annotations=d.entries))
    return out


def _frames(ctx: LowerContext) -> dict[str, FrameDef]:
    return ctx.model.frames.entries if ctx.model.frames is not None else {}


def _is_new(d: FrameDef) -> bool:
    return d.joint is not None or d.parent is not None


def new_frames(ctx: LowerContext) -> list[Op]:
    return [_new_frame(ctx, name, d) for name, d in _frames(ctx).items() if _is_new(d)]


def _new_frame(ctx: LowerContext, name: str, d: FrameDef) -> Op:
    j = d.joint
    src: Node = j if j is not None else d
    parent = j.parent if j is not None else d.parent
    for key in ("transform_link", "transform_frame", "reparent_to"):
        if getattr(d, key) is not None:
            ctx.sink.error(d.key_span(key), "E0313", f"new frame '{name}' cannot have "
                           f"'{key}': give its pose in its joint instead")
    xyz = ctx.vec(src, "xyz", f"frame '{name}' xyz") or (0.0, 0.0, 0.0)
    rpy = ctx.vec(src, "rpy", f"frame '{name}' rpy") or (0.0, 0.0, 0.0)
    joint = (j.name if j is not None else d.jointname) or name
    return ops.AddFrame(span=d.span, link=name, parent=parent or "", joint=joint,
                        type=(j.type if j is not None else d.type) or "fixed", xyz=xyz, rpy=rpy,
                        axis=ctx.vec(src, "axis", f"frame '{name}' axis"),
                        mass=ctx.num(d, "mass", f"frame '{name}' mass"), annotations=d.entries,
                        spans={"parent": src.value_span("parent"), "link": d.span})


def make_root(ctx: LowerContext) -> list[Op]:
    roots = [(n, d) for n, d in _frames(ctx).items() if d.make_root]
    for name, d in roots[1:]:
        ctx.sink.error(d.key_span("make_root"), "E0313", f"make_root on '{name}': only one "
                       f"link can be the root, and '{roots[0][0]}' is made root already")
    return [ops.MakeRoot(span=roots[0][1].key_span("make_root"), link=roots[0][0])] if roots else []


def frame_defaults(ctx: LowerContext) -> list[Op]:
    section = ctx.model.frames
    if section is None or section.default is None:
        return []
    refuse(ctx, section.default, "frames $default", _NOT_IN_FRAME_DEFAULT)
    return _link_edits(ctx, "", section.default, all_links=True)


def frame_edits(ctx: LowerContext) -> list[Op]:
    out: list[Op] = []
    for name, d in _frames(ctx).items():
        if not _is_new(d):
            refuse(ctx, d, f"frame '{name}' (an existing link; give it a parent to add a new frame)",
                   _NEW_FRAME_ONLY)
        out += _link_edits(ctx, name, d, all_links=False, is_new=_is_new(d))
    return out


def frame_names(ctx: LowerContext) -> list[Op]:
    return [scoped_names(ctx, d.name_editing, f"frames.{name}.name_editing", "link", only=(name,))
            for name, d in _frames(ctx).items() if d.name_editing is not None]


def frames_names(ctx: LowerContext) -> list[Op]:
    section = ctx.model.frames
    if section is None or section.name_editing is None:
        return []
    return [scoped_names(ctx, section.name_editing, "frames.$name_editing", "link")]


def _link_edits(ctx: LowerContext, name: str, d: FrameDef, *, all_links: bool,
                is_new: bool = False) -> list[Op]:
    out: list[Op] = []
    links = () if all_links else (name,)
    spans = {"link": d.span, "links": d.span, "parent": d.value_span("reparent_to"),
             "material": d.value_span("material")}
    for key, op in (("transform_link", ops.TransformLink), ("transform_frame", ops.TransformFrame)):
        t = getattr(d, key)
        if t is not None and not all_links:
            out.append(op(span=d.key_span(key), link=name, spans=spans,
                          xyz=ctx.vec(t, "xyz", f"{key} of '{name}'") or (0.0, 0.0, 0.0),
                          rpy=ctx.vec(t, "rpy", f"{key} of '{name}'") or (0.0, 0.0, 0.0)))
    if d.reparent_to is not None and not all_links:
        out.append(ops.ReparentLink(span=d.key_span("reparent_to"), link=name, parent=d.reparent_to,
                                    spans=spans))
    if d.estimate_missing_coms:
        out.append(ops.EstimateMissingComs(span=d.key_span("estimate_missing_coms"), links=links,
                                           spans=spans))
    if d.estimate_missing_inertia:
        out.append(ops.EstimateMissingInertia(span=d.key_span("estimate_missing_inertia"), links=links,
                                              spans=spans))
    if (d.entries and not is_new) or d.material:
        out.append(ops.AnnotateLinks(span=d.span, links=links, material=d.material,
                                     annotations={} if is_new else d.entries, spans=spans))
    return out


# -- joints -------------------------------------------------------------------------------

def _joints(ctx: LowerContext) -> dict[str, JointDef]:
    return ctx.model.joints.entries if ctx.model.joints is not None else {}


def _values(ctx: LowerContext, d: Any, what: str) -> JointValues:
    from mpc.ir.ops.joints import JointValues

    return JointValues(**{field: ctx.num(d, key, f"{what} {key}")
                          for key, field in _LIMIT_KEYS.items() if hasattr(d, key)})


def replace_joint_types(ctx: LowerContext) -> list[Op]:
    section = ctx.model.joints
    if section is None or not section.replace_joint_types:
        return []
    return [ops.ReplaceJointTypes(span=section.key_span("$replace_joint_types"),
                                  mapping=tuple(section.replace_joint_types.items()))]


def cut_joints(ctx: LowerContext) -> list[Op]:
    out: list[Op] = []
    for name, d in _joints(ctx).items():
        if not d.cut_joint:
            continue
        if d.parent is None or d.child is None:
            ctx.sink.error(d.key_span("cut_joint"), "E0314",
                           f"cut joint '{name}' needs 'parent' and 'child' links")
            continue
        axes = tuple((a.name, ctx.vec(a, "axis", f"cut joint '{name}' axis") or (0.0, 0.0, 0.0))
                     for a in d.constraint_axes or [])
        out.append(ops.AddCutJoint(span=d.span, joint=name, parent=d.parent, child=d.child,
                                   type=d.type or "fixed", constraint_axes=axes,  # type: ignore[arg-type]
                                   annotations=d.entries, spans=_spans(d, "parent", "child")))
    return out


def joint_defaults(ctx: LowerContext) -> list[Op]:
    section = ctx.model.joints
    if section is None or section.default is None:
        return []
    refuse(ctx, section.default, "joints $default", _NOT_IN_JOINT_DEFAULT)
    listed = () if section.all else tuple(n for n, d in section.entries.items()
                                          if not d.cut_joint and not d.remove)
    return [ops.JointDefaults(span=section.key_span("$default"), joints=listed,
                              values=_values(ctx, section.default, "joints $default"),
                              annotations=section.default.entries,
                              spans={"joints": section.key_span("$default")})]


def joint_backup(ctx: LowerContext) -> list[Op]:
    section = ctx.model.joints
    if section is None or section.backup is None:
        return []
    return [ops.JointDefaults(span=section.key_span("$backup"), backup=True,
                              values=_values(ctx, section.backup, "joints $backup"))]


def joint_edits(ctx: LowerContext) -> list[Op]:
    out: list[Op] = []
    for name, d in _joints(ctx).items():
        if not d.cut_joint and not d.remove:
            out += _joint_edits(ctx, name, d)
    return out


def joint_removals(ctx: LowerContext) -> list[Op]:
    return [ops.RemoveJoint(span=d.key_span("remove"), joint=name, spans={"joint": d.span})
            for name, d in _joints(ctx).items() if d.remove]


def joint_names(ctx: LowerContext) -> list[Op]:
    return [scoped_names(ctx, d.name_editing, f"joints.{name}.name_editing", "joint", only=(name,))
            for name, d in _joints(ctx).items() if d.name_editing is not None]


def joints_names(ctx: LowerContext) -> list[Op]:
    section = ctx.model.joints
    if section is None or section.name_editing is None:
        return []
    return [scoped_names(ctx, section.name_editing, "joints.$name_editing", "joint")]


def _joint_edits(ctx: LowerContext, name: str, d: JointDef) -> list[Op]:
    from mpc.ir.ops.joints import Dependency

    what = f"joint '{name}'"
    deps = tuple(Dependency(joint=x.joint, multiplier=ctx.num(x, "multiplier", what) or 0.0,
                            offset=ctx.num(x, "offset", what) or 0.0)
                 for x in d.movement_depends_on or [])
    mimic = None
    if d.mimic is not None:
        mimic = Dependency(joint=d.mimic.joint,
                           multiplier=ctx.num(d.mimic, "multiplier", f"{what} mimic") or 0.0,
                           offset=ctx.num(d.mimic, "offset", f"{what} mimic") or 0.0)
    spans = {"joint": d.span, "mimic": d.value_span("mimic") if d.mimic else
             d.value_span("movement_depends_on")}
    out: list[Op] = [ops.EditJoint(span=d.span, joint=name, values=_values(ctx, d, what), type=d.type,
                                   axis=ctx.vec(d, "axis", f"{what} axis"),  # type: ignore[arg-type]
                                   mimic=mimic, depends_on=deps, annotations=d.entries, spans=spans)]
    motor = _motor(ctx, name, d)
    if motor is not None:
        out.append(motor)
    if d.move_joint_axis_to_intersection:
        a, b = d.move_joint_axis_to_intersection
        key = "move_joint_axis_to_intersection"
        out.append(ops.MoveJointAxisToIntersection(
            span=d.key_span(key), joint=name, a=a, b=b,
            spans={"a": d.value_span(key, 0), "b": d.value_span(key, 1)}))
    return out


def _motor(ctx: LowerContext, name: str, d: JointDef) -> SetMotor | None:
    given = [m for m in (d.active, d.motor) if m not in (None, False)]
    if not given:
        return None
    settings: dict[str, Any] = {}
    motor_name = f"{name}_motor"
    for m in given:
        if isinstance(m, MotorDef):
            for key in ("p", "i", "d", "maxEffort", "maxSpeed"):
                if getattr(m, key) is not None:
                    settings[key] = ctx.num(m, key, f"motor of joint '{name}' {key}")
            if m.type is not None:
                settings["type"] = m.type
            settings.update(m.entries)
            motor_name = m.name or motor_name
    key = "active" if d.active not in (None, False) else "motor"
    return ops.SetMotor(span=d.key_span(key), joint=name, name=motor_name, settings=settings,
                        spans={"joint": d.span})


# -- collisions, visuals ------------------------------------------------------------------

def collisions_names(ctx: LowerContext) -> list[Op]:
    section = ctx.model.collisions
    if section is None or section.name_editing is None:
        return []
    return [scoped_names(ctx, section.name_editing, "collisions.$name_editing", "collision")]


def _defaults_then_entries(section: Any) -> list[tuple[str, Any]]:
    """`$default` (target "") first, then the entries by name."""
    todo = [("", section.default)] if section.default is not None else []
    return todo + list(section.entries.items())


def collision_edits(ctx: LowerContext) -> list[Op]:
    section = ctx.model.collisions
    if section is None:
        return []
    out: list[Op] = []
    for target, d in _defaults_then_entries(section):
        remove = removal(ctx, d, f"collisions of '{target or '$default'}'")
        out.append(ops.EditCollisions(
            span=d.span, target=target, phobos_default=target == "default",
            exclude=tuple(section.exclude) if not target else (),
            remove=remove, shape=d.shape, oriented=d.oriented, replace=section.apply_primitives,
            scale=ctx.num(d, "scale", f"collision '{target}' scale") or 1.0, join=d.join,
            bitmask=d.bitmask,
            annotations={**d.entries, **({"ccfm": ctx.num(d, "ccfm", f"collision '{target}' ccfm")}
                                         if d.ccfm is not None else {})},
            spans={"target": d.span, "exclude": section.value_span("$exclude")}))
    return out


def bitmasks(ctx: LowerContext) -> list[Op]:
    section = ctx.model.collisions
    if section is None:
        return []
    pairs = {k: tuple((a, b) for a, bs in getattr(section, k).items() for b in bs)
             for k in ("no_collision_between", "collision_between")}
    if section.auto_bitmask:
        spans = {f"pair/{a}": section.key_span(k) for k in pairs for a, _ in pairs[k]}
        spans.update({f"pair/{a}/{b}": pair_span(section, k, a, b) for k in pairs for a, b in pairs[k]})
        return [ops.AutoBitmask(span=section.key_span("auto_bitmask"), spans=spans,
                                never=pairs["no_collision_between"], always=pairs["collision_between"])]
    for key in pairs:
        if pairs[key]:
            ctx.sink.warning(section.key_span(key), "W0301",
                             f"'{key}' has no effect without 'auto_bitmask: true'")
    return []


def visuals_names(ctx: LowerContext) -> list[Op]:
    section = ctx.model.visuals
    if section is None or section.name_editing is None:
        return []
    return [scoped_names(ctx, section.name_editing, "visuals.$name_editing", "visual")]


def visual_edits(ctx: LowerContext) -> list[Op]:
    section = ctx.model.visuals
    if section is None:
        return []
    return [ops.EditVisuals(span=d.span, targets=(target,) if target else (),
                            exclude=tuple(section.exclude) if not target else (),
                            remove=removal(ctx, d, f"visuals of '{target or '$default'}'"),
                            material=d.material,
                            annotations=d.entries,
                            spans={"targets": d.span, "exclude": section.value_span("$exclude"),
                                   "material": d.value_span("material")})
            for target, d in _defaults_then_entries(section)]


# -- submechanisms, sensors, poses, annotations, meshes ------------------------------------

def submechanisms(ctx: LowerContext) -> list[Op]:
    m = ctx.model
    out: list[Op] = []
    if m.submechanisms_file is not None:
        if m.submechanisms or m.exoskeletons:
            ctx.sink.error(m.key_span("submechanisms_file"), "E0315", "give either "
                           "'submechanisms_file' or 'submechanisms'/'exoskeletons', not both")
            return []
        folder = ctx.folder_of(m, "submechanisms_file")
        path = resolved(folder / m.submechanisms_file)
        if not path.is_file():
            ctx.sink.error(m.value_span("submechanisms_file"), "E0601",
                           f"submechanisms_file '{path}' does not exist")
        elif why := input_problem(folder / m.submechanisms_file, (project_root(folder),)):
            ctx.sink.error(m.value_span("submechanisms_file"), "E0650",
                           f"submechanisms_file '{m.submechanisms_file}' is not read: {why}")
            return []
        out.append(ops.SubmechanismsFile(span=m.value_span("submechanisms_file"), path=str(path)))
    for exo, items in ((False, m.submechanisms or []), (True, m.exoskeletons or [])):
        for s in items:
            joints: list[str] = []
            for key in ("jointnames_independent", "jointnames_spanningtree", "jointnames_active",
                        "jointnames", "jointnames_dependent"):
                joints += [j for j in getattr(s, key, []) if j not in joints]
            links = [b for lc in getattr(s, "loop_constraints", [])
                     for b in (lc.predecessor_body, lc.successor_body)]
            # `around` names the human the exoskeleton is worn around (Phobos stores it as written,
            # `around: human`), not necessarily a link: it is not checked
            out.append(ops.AddSubmechanism(span=s.span, name=s.name, exoskeleton=exo, joints=tuple(joints),
                                           links=tuple(dict.fromkeys(links)), definition=s.to_data()))
    if m.submechanisms or m.exoskeletons:
        span = m.key_span("submechanisms" if m.submechanisms else "exoskeletons")
        out.append(ops.CompleteSubmechanisms(span=span))
    return out


def sensors(ctx: LowerContext) -> list[Op]:
    if ctx.model.sensors is None:
        return []
    out: list[Op] = []
    for kind, d in sensor_entries(ctx.model.sensors):
        if kind and d.type and d.type != kind:
            ctx.sink.error(d.value_span("type"), "E0316", f"sensor '{d.name}' is listed under "
                           f"{kind} but says type {d.type}")
            continue
        kind = kind or d.type
        if kind is None:
            ctx.sink.error(d.span, "E0316", f"sensor '{d.name}' has no 'type'")
            continue
        if kind in SINGLE_LINK_SENSORS and d.link is None and d.joint is None:
            ctx.sink.error(d.span, "E0316", f"{kind} sensor '{d.name}' needs a 'link'")
            continue
        targets = tuple(d.targets or ())
        if kind in MULTI_LINK_SENSORS and not targets:
            ctx.sink.warning(d.span, "W0265", f"{kind} sensor '{d.name}' has no 'targets': it measures "
                             "nothing (Phobos gives it an empty list of targets)",
                             hint="give 'targets': a list of names, or All")
        if len(targets) == 1 and targets[0].upper() == "ALL":
            targets = ("All",)  # Phobos's word in any case: every movable joint
        out.append(ops.AddSensor(
            span=d.span, type=kind, name=d.name, link=d.link, joint=d.joint, frame=d.frame,
            targets=targets, targets_kind="link" if kind.startswith("Node") else "joint",
            position_offset=ctx.vec(d, "position_offset", f"sensor '{d.name}' position_offset"),
            orientation_offset=ctx.vec(d, "orientation_offset", f"sensor '{d.name}' orientation"),
            annotations=d.entries, spans=_spans(d, "link", "joint", "frame", "targets")))
    return out


def poses(ctx: LowerContext) -> list[Op]:
    """One op per pose. A number for `$default` (Phobos's form) is every pose's value of the
    movable joints it does not list, unless the pose has a `$default` of its own."""
    out: list[Op] = []
    section = ctx.model.poses
    if section is None:
        return out
    default = ctx.num(section, "default", "poses' $default")
    for name, pose in section.entries.items():
        positions = {j: ctx.num_value(v, pose.value_span(j), f"pose '{name}' joint '{j}'")
                     for j, v in pose.entries.items()}
        own = ctx.num(pose, "default", f"pose '{name}' $default")
        out.append(ops.AddPose(span=pose.span, name=name, positions=positions,  # type: ignore[arg-type]
                               default=own if own is not None else default,
                               spans={f"positions/{j}": pose.key_span(j) for j in positions}))
    return out


def annotations(ctx: LowerContext) -> list[Op]:
    section = ctx.model.annotations
    if section is None:
        return []
    out: list[Op] = [ops.AddAnnotations(span=section.key_span("named_annotations"), category=category,
                                        content=content)
                     for category, content in section.named_annotations.items()]
    general = section.general_annotations
    if isinstance(general, list):
        return out + _annotation_pairs(ctx, section, general)
    if general:
        out.append(ops.AddAnnotations(span=section.key_span("general_annotations"), category="annotations",
                                      content=general))
    return out


def _annotation_pairs(ctx: LowerContext, section: Node, pairs: list[list[Any]]) -> list[Op]:
    """Phobos's `general_annotations`: [category, content] pairs, each the category's content
    (`<robot>_<category>.yml`); the mappings of a category given twice are merged. A content
    that is no mapping goes into the category `annotations` under its name (W0262)."""
    categories: dict[str, dict[str, Any]] = {}
    loose: dict[str, Any] = {}
    for i, (category, content) in enumerate(pairs):
        span = section.value_span("general_annotations", i)
        if not isinstance(category, str) or not category:
            ctx.sink.error(span, "E0203", "a general_annotations pair is [category, content], the category "
                           f"a name; got {category!r}")
        elif isinstance(content, dict):
            categories.setdefault(category, {}).update(content)
        else:
            ctx.sink.warning(span, "W0262", f"general_annotations: the content of '{category}' is no "
                             f"mapping; mpc writes it in the category 'annotations' as '{category}' "
                             f"(Phobos writes it to its own file, <robot>_{category}.yml)")
            loose[category] = content
    span = section.key_span("general_annotations")
    out: list[Op] = [ops.AddAnnotations(span=span, category=c, content=v) for c, v in categories.items()]
    if loose:
        out.append(ops.AddAnnotations(span=span, category="annotations", content=loose))
    return out


def mesh_ops(ctx: LowerContext) -> list[Op]:
    """`apply_scale` and `reduce_meshes`, after every edit (they act on the final meshes)."""
    m = ctx.model
    if not m.apply_scale and m.reduce_meshes is None:
        return []
    from mpc.ir.ops.meshes import ApplyScale, ReduceMeshes  # imported only for a definition that asks

    out: list[Op] = [ApplyScale(span=m.key_span("apply_scale"))] if m.apply_scale else []
    if m.reduce_meshes is not None:
        value = ctx.num(m, "reduce_meshes", "reduce_meshes")
        if value is None:
            return out
        if 0 < value < 1:
            out.append(ReduceMeshes(span=m.value_span("reduce_meshes"), ratio=value))
        elif value >= 4 and float(value).is_integer():
            out.append(ReduceMeshes(span=m.value_span("reduce_meshes"), faces=int(value)))
        else:
            ctx.sink.error(m.value_span("reduce_meshes"), "E0203",
                           "'reduce_meshes' is a ratio of faces to keep (between 0 and 1) or a "
                           f"number of faces (4 or more), got {value:g}")
    return out


# The language's order of the edits of the assembled robot (see the module docstring).
EDIT_STEPS: tuple[Step, ...] = (
    materials,
    new_frames, make_root, frame_defaults, frame_edits, frame_names, frames_names,
    replace_joint_types, cut_joints, joint_defaults, joint_backup, joint_edits, joint_removals,
    joint_names, joints_names,
    collisions_names, collision_edits, bitmasks,
    visuals_names, visual_edits,
    submechanisms, sensors, poses, annotations,
    mesh_ops,
)


def lower_edits(ctx: LowerContext) -> list[Op]:
    """The ops of the editing sections, in the order of EDIT_STEPS."""
    return [op for step in EDIT_STEPS for op in step(ctx)]


# Keys that belong to a new frame's joint, and mean nothing on an existing link.
_NEW_FRAME_ONLY = ("parent", "jointname", "xyz", "rpy", "axis", "type", "mass", "joint")
# Keys that act on one link, and mean nothing in frames' $default.
_NOT_IN_FRAME_DEFAULT = ("transform_link", "transform_frame", "reparent_to", "make_root", "name_editing",
                         *_NEW_FRAME_ONLY)
# Keys that act on one joint, and mean nothing in joints' $default.
_NOT_IN_JOINT_DEFAULT = ("type", "axis", "remove", "cut_joint", "parent", "child", "constraint_axes",
                         "move_joint_axis_to_intersection", "mimic", "movement_depends_on", "active",
                         "motor", "name_editing")
