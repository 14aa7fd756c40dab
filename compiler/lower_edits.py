"""Editing sections of the AST → ops, in the order the language fixes.

Sections: materials, frames, joints, collisions, visuals, submechanisms, sensors,
poses, annotations. Within frames: new frames, make_root, per-link edits, per-link
name editing, `$name_editing`; within joints: `$replace_joint_types`, cut joints,
`$default`, per-joint edits, removals, name editing; within collisions: name
editing, then per-entry edits, then bitmasks (Phobos's order, §2.8).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mpc.compiler.schema.annotations import MULTI_LINK_SENSORS, SINGLE_LINK_SENSORS, sensor_entries
from mpc.compiler.schema.base import Node
from mpc.compiler.schema.editing import FrameDef, JointDef, MotorDef
from mpc.ir import ops

if TYPE_CHECKING:
    from mpc.compiler.lower import _Lowering
    from mpc.ir.ops import SetMotor
    from mpc.ir.ops.joints import JointValues

_LIMIT_KEYS = {"min": "lower", "max": "upper", "eff": "effort", "vel": "velocity", "friction": "friction",
               "damping": "damping", "spring_stiffness": "spring_stiffness",
               "spring_reference": "spring_reference"}


def _spans(node: Node, *keys: str) -> dict[str, Any]:
    return {k: node.value_span(k) for k in keys}


class EditLowering:
    """Appends the ops of the editing sections to a _Lowering's op list."""

    def __init__(self, lw: _Lowering) -> None:
        self.lw, self.model, self.sink = lw, lw.model, lw.sink

    def add(self, op: Any) -> None:
        self.lw.ops.append(op)

    def removal(self, d: Any, what: str) -> bool | tuple[str, ...]:
        """`remove`: true, or names and regular expressions (checked here, E0305)."""
        if isinstance(d.remove, bool):
            return d.remove
        from mpc.ir.naming import bad_pattern

        kept = []
        for i, pattern in enumerate(d.remove):
            problem = bad_pattern(pattern)
            if problem:
                span = self.lw.item_span(d, "remove", i) if isinstance(
                    d._doc.data_at((*d._path, "remove")), list) else d.value_span("remove")
                self.sink.error(span, "E0305", f"'{pattern}' in {what} remove is not a regular "
                                f"expression: {problem}")
            else:
                kept.append(pattern)
        return tuple(kept)

    def run(self) -> None:
        m = self.model
        for name, d in m.materials.items():
            self.material(name, d)
        if m.frames is not None:
            self.frames()
        if m.joints is not None:
            self.joints()
        if m.collisions is not None:
            self.collisions()
        if m.visuals is not None:
            self.visuals()
        self.submechanisms()
        if m.sensors is not None:
            self.sensors()
        for name, pose in m.poses.items():
            positions = {j: self.lw.num_value(v, pose.value_span(j), f"pose '{name}' joint '{j}'")
                         for j, v in pose.entries.items()}
            self.add(ops.AddPose(span=pose.span, name=name, positions=positions,  # type: ignore[arg-type]
                                 default=self.lw.num(pose, "default", f"pose '{name}' $default"),
                                 spans={f"positions/{j}": pose.key_span(j) for j in positions}))
        if m.annotations is not None:
            for category, content in m.annotations.named_annotations.items():
                self.add(ops.AddAnnotations(span=m.annotations.key_span("named_annotations"),
                                            category=category, content=content))
            if m.annotations.general_annotations:
                self.add(ops.AddAnnotations(span=m.annotations.key_span("general_annotations"),
                                            category="annotations",
                                            content=m.annotations.general_annotations))

    # -- materials and frames -------------------------------------------------------------

    def refuse(self, d: Node, where: str, keys: tuple[str, ...]) -> None:
        """Report keys that mean nothing in this place (instead of ignoring them)."""
        for key in keys:
            if key in d.given:
                self.sink.error(d.key_span(key), "E0313", f"'{key}' has no meaning in {where}")

    def scoped(self, editing: Any, where: str, scope: str) -> None:
        """Name editing of one kind of name: the keys of other kinds would do nothing, nor the
        flags of an assembly entry's name_editing, which rename by the tree."""
        flags = {"joint_equals_link_name", "append_link_suffix"}
        for key in sorted(editing.given & flags):
            self.sink.error(editing.key_span(key), "E0313", f"'{key}' has no meaning in {where}; "
                            "it is a key of an assemble entry's name_editing")
        for key in editing.given - flags:
            kind = key.split("_", 1)[0]
            if "_" in key and kind in ("link", "joint", "collision", "visual", "submechanism") \
                    and kind != scope:
                self.sink.error(editing.key_span(key), "E0313", f"'{key}' has no meaning in {where}, "
                                f"which renames {scope}s only")

    def material(self, name: str, d: Any) -> None:
        colours = {k: self.lw.vec(d, k, f"material '{name}' {k}") for k in
                   ("diffuse", "ambient", "specular", "emissive")}
        self.add(ops.EditMaterial(span=d.span, name=name, **colours, texture=d.texture,
                                  normal_texture=d.normalTexture,
                                  shininess=self.lw.num(d, "shininess", f"material '{name}' shininess"),
                                  transparency=self.lw.num(d, "transparency",
                                                           f"material '{name}' transparency"),
                                  annotations=d.entries))

    def frames(self) -> None:
        section = self.model.frames
        assert section is not None
        entries: dict[str, FrameDef] = section.entries
        new = {n: d for n, d in entries.items() if d.joint is not None or d.parent is not None}
        for name, d in new.items():
            self.new_frame(name, d)
        roots = [(n, d) for n, d in entries.items() if d.make_root]
        for name, d in roots[1:]:
            self.sink.error(d.key_span("make_root"), "E0313", f"make_root on '{name}': only one "
                            f"link can be the root, and '{roots[0][0]}' is made root already")
        if roots:
            self.add(ops.MakeRoot(span=roots[0][1].key_span("make_root"), link=roots[0][0]))
        if section.default is not None:
            self.refuse(section.default, "frames $default", _NOT_IN_FRAME_DEFAULT)
            self.link_edits("", section.default, all_links=True)
        for name, d in entries.items():
            if name not in new:
                self.refuse(d, f"frame '{name}' (an existing link; give it a parent to add a new frame)",
                            _NEW_FRAME_ONLY)
            self.link_edits(name, d, all_links=False, is_new=name in new)
        for name, d in entries.items():
            if d.name_editing is not None:
                self.scoped(d.name_editing, f"frames.{name}.name_editing", "link")
                self.add(ops.EditNames(span=d.name_editing.span, rules=self.lw.name_rules(d.name_editing),
                                       kinds=("link",), only=(name,)))
        if section.name_editing is not None:
            self.scoped(section.name_editing, "frames.$name_editing", "link")
            self.add(ops.EditNames(span=section.name_editing.span, kinds=("link",),
                                   rules=self.lw.name_rules(section.name_editing)))

    def new_frame(self, name: str, d: FrameDef) -> None:
        j = d.joint
        src: Node = j if j is not None else d
        parent = j.parent if j is not None else d.parent
        for key in ("transform_link", "transform_frame", "reparent_to"):
            if getattr(d, key) is not None:
                self.sink.error(d.key_span(key), "E0313", f"new frame '{name}' cannot have "
                                f"'{key}': give its pose in its joint instead")
        xyz = self.lw.vec(src, "xyz", f"frame '{name}' xyz") or (0.0, 0.0, 0.0)
        rpy = self.lw.vec(src, "rpy", f"frame '{name}' rpy") or (0.0, 0.0, 0.0)
        joint = (j.name if j is not None else d.jointname) or name
        self.add(ops.AddFrame(span=d.span, link=name, parent=parent or "", joint=joint,  # type: ignore[arg-type]
                              type=(j.type if j is not None else d.type) or "fixed", xyz=xyz, rpy=rpy,
                              axis=self.lw.vec(src, "axis", f"frame '{name}' axis"),
                              mass=self.lw.num(d, "mass", f"frame '{name}' mass"), annotations=d.entries,
                              spans={"parent": src.value_span("parent"), "link": d.span}))

    def link_edits(self, name: str, d: FrameDef, *, all_links: bool, is_new: bool = False) -> None:
        links = () if all_links else (name,)
        spans = {"link": d.span, "links": d.span, "parent": d.value_span("reparent_to"),
                 "material": d.value_span("material")}
        for key, op in (("transform_link", ops.TransformLink), ("transform_frame", ops.TransformFrame)):
            t = getattr(d, key)
            if t is not None and not all_links:
                self.add(op(span=d.key_span(key), link=name, spans=spans,
                            xyz=self.lw.vec(t, "xyz", f"{key} of '{name}'") or (0.0, 0.0, 0.0),
                            rpy=self.lw.vec(t, "rpy", f"{key} of '{name}'") or (0.0, 0.0, 0.0)))
        if d.reparent_to is not None and not all_links:
            self.add(ops.ReparentLink(span=d.key_span("reparent_to"), link=name, parent=d.reparent_to,
                                      spans=spans))
        if d.estimate_missing_coms:
            self.add(ops.EstimateMissingComs(span=d.key_span("estimate_missing_coms"), links=links,
                                             spans=spans))
        if d.estimate_missing_inertia:
            self.add(ops.EstimateMissingInertia(span=d.key_span("estimate_missing_inertia"), links=links,
                                                spans=spans))
        if (d.entries and not is_new) or d.material:
            self.add(ops.AnnotateLinks(span=d.span, links=links, material=d.material,
                                       annotations={} if is_new else d.entries, spans=spans))

    # -- joints ----------------------------------------------------------------------------

    def values(self, d: Any, what: str) -> JointValues:
        from mpc.ir.ops.joints import JointValues

        return JointValues(**{field: self.lw.num(d, key, f"{what} {key}")
                              for key, field in _LIMIT_KEYS.items() if hasattr(d, key)})

    def joints(self) -> None:
        section = self.model.joints
        assert section is not None
        entries: dict[str, JointDef] = section.entries
        if section.replace_joint_types:
            self.add(ops.ReplaceJointTypes(span=section.key_span("$replace_joint_types"),
                                           mapping=tuple(section.replace_joint_types.items())))
        for name, d in entries.items():
            if d.cut_joint:
                self.cut_joint(name, d)
        if section.default is not None:
            self.refuse(section.default, "joints $default", _NOT_IN_JOINT_DEFAULT)
            listed = () if section.all else tuple(n for n, d in entries.items()
                                                  if not d.cut_joint and not d.remove)
            self.add(ops.JointDefaults(span=section.key_span("$default"), joints=listed,
                                       values=self.values(section.default, "joints $default"),
                                       annotations=section.default.entries,
                                       spans={"joints": section.key_span("$default")}))
        if section.backup is not None:
            self.add(ops.JointDefaults(span=section.key_span("$backup"), backup=True,
                                       values=self.values(section.backup, "joints $backup")))
        for name, d in entries.items():
            if not d.cut_joint and not d.remove:
                self.joint_edits(name, d)
        for name, d in entries.items():
            if d.remove:
                self.add(ops.RemoveJoint(span=d.key_span("remove"), joint=name, spans={"joint": d.span}))
        for name, d in entries.items():
            if d.name_editing is not None:
                self.scoped(d.name_editing, f"joints.{name}.name_editing", "joint")
                self.add(ops.EditNames(span=d.name_editing.span, rules=self.lw.name_rules(d.name_editing),
                                       kinds=("joint",), only=(name,)))
        if section.name_editing is not None:
            self.scoped(section.name_editing, "joints.$name_editing", "joint")
            self.add(ops.EditNames(span=section.name_editing.span, kinds=("joint",),
                                   rules=self.lw.name_rules(section.name_editing)))

    def cut_joint(self, name: str, d: JointDef) -> None:
        if d.parent is None or d.child is None:
            self.sink.error(d.key_span("cut_joint"), "E0314",
                            f"cut joint '{name}' needs 'parent' and 'child' links")
            return
        axes = tuple((a.name, self.lw.vec(a, "axis", f"cut joint '{name}' axis") or (0.0, 0.0, 0.0))
                     for a in d.constraint_axes or [])
        self.add(ops.AddCutJoint(span=d.span, joint=name, parent=d.parent, child=d.child,
                                 type=d.type or "fixed", constraint_axes=axes,  # type: ignore[arg-type]
                                 annotations=d.entries, spans=_spans(d, "parent", "child")))

    def joint_edits(self, name: str, d: JointDef) -> None:
        from mpc.ir.ops.joints import Dependency

        what = f"joint '{name}'"
        deps = tuple(Dependency(joint=x.joint, multiplier=self.lw.num(x, "multiplier", what) or 0.0,
                                offset=self.lw.num(x, "offset", what) or 0.0)
                     for x in d.movement_depends_on or [])
        mimic = None
        if d.mimic is not None:
            mimic = Dependency(joint=d.mimic.joint,
                               multiplier=self.lw.num(d.mimic, "multiplier", f"{what} mimic") or 0.0,
                               offset=self.lw.num(d.mimic, "offset", f"{what} mimic") or 0.0)
        spans = {"joint": d.span, "mimic": d.value_span("mimic") if d.mimic else
                 d.value_span("movement_depends_on")}
        self.add(ops.EditJoint(span=d.span, joint=name, values=self.values(d, what), type=d.type,
                               axis=self.lw.vec(d, "axis", f"{what} axis"),  # type: ignore[arg-type]
                               mimic=mimic, depends_on=deps, annotations=d.entries, spans=spans))
        motor = self.motor(name, d)
        if motor is not None:
            self.add(motor)
        if d.move_joint_axis_to_intersection:
            a, b = d.move_joint_axis_to_intersection
            key = "move_joint_axis_to_intersection"
            self.add(ops.MoveJointAxisToIntersection(
                span=d.key_span(key), joint=name, a=a, b=b,
                spans={"a": self.lw.item_span(d, key, 0), "b": self.lw.item_span(d, key, 1)}))

    def motor(self, name: str, d: JointDef) -> SetMotor | None:
        given = [m for m in (d.active, d.motor) if m not in (None, False)]
        if not given:
            return None
        settings: dict[str, Any] = {}
        motor_name = f"{name}_motor"
        for m in given:
            if isinstance(m, MotorDef):
                for key in ("p", "i", "d", "maxEffort", "maxSpeed"):
                    if getattr(m, key) is not None:
                        settings[key] = self.lw.num(m, key, f"motor of joint '{name}' {key}")
                if m.type is not None:
                    settings["type"] = m.type
                settings.update(m.entries)
                motor_name = m.name or motor_name
        key = "active" if d.active not in (None, False) else "motor"
        return ops.SetMotor(span=d.key_span(key), joint=name, name=motor_name, settings=settings,
                            spans={"joint": d.span})

    # -- collisions, visuals ---------------------------------------------------------------

    def collisions(self) -> None:
        section = self.model.collisions
        assert section is not None
        if section.name_editing is not None:
            self.scoped(section.name_editing, "collisions.$name_editing", "collision")
            self.add(ops.EditNames(span=section.name_editing.span, kinds=("collision",),
                                   rules=self.lw.name_rules(section.name_editing)))
        todo = [("", section.default)] if section.default is not None else []
        todo += list(section.entries.items())
        for target, d in todo:
            remove = self.removal(d, f"collisions of '{target or '$default'}'")
            self.add(ops.EditCollisions(
                span=d.span, target=target, exclude=tuple(section.exclude) if not target else (),
                remove=remove, shape=d.shape, oriented=d.oriented, replace=section.apply_primitives,
                scale=self.lw.num(d, "scale", f"collision '{target}' scale") or 1.0, join=d.join,
                bitmask=d.bitmask,
                annotations={**d.entries, **({"ccfm": self.lw.num(d, "ccfm", f"collision '{target}' ccfm")}
                                             if d.ccfm is not None else {})},
                spans={"target": d.span, "exclude": section.value_span("$exclude")}))
        pairs = {k: tuple((a, b) for a, bs in getattr(section, k).items() for b in bs)
                 for k in ("no_collision_between", "collision_between")}
        if section.auto_bitmask:
            spans = {f"pair/{a}": section.key_span(k) for k in pairs for a, _ in pairs[k]}
            spans.update({f"pair/{a}/{b}": self.lw.pair_span(section, k, a, b)
                          for k in pairs for a, b in pairs[k]})
            self.add(ops.AutoBitmask(span=section.key_span("auto_bitmask"), spans=spans,
                                     never=pairs["no_collision_between"], always=pairs["collision_between"]))
        else:
            for key in pairs:
                if pairs[key]:
                    self.sink.warning(section.key_span(key), "W0301",
                                      f"'{key}' has no effect without 'auto_bitmask: true'")

    def visuals(self) -> None:
        section = self.model.visuals
        assert section is not None
        if section.name_editing is not None:
            self.scoped(section.name_editing, "visuals.$name_editing", "visual")
            self.add(ops.EditNames(span=section.name_editing.span, kinds=("visual",),
                                   rules=self.lw.name_rules(section.name_editing)))
        todo = [("", section.default)] if section.default is not None else []
        todo += list(section.entries.items())
        for target, d in todo:
            self.add(ops.EditVisuals(
                span=d.span, targets=(target,) if target else (),
                exclude=tuple(section.exclude) if not target else (),
                remove=self.removal(d, f"visuals of '{target or '$default'}'"), material=d.material,
                annotations=d.entries,
                spans={"targets": d.span, "exclude": section.value_span("$exclude"),
                       "material": d.value_span("material")}))

    # -- submechanisms, sensors ------------------------------------------------------------

    def submechanisms(self) -> None:
        m = self.model
        lists = [(False, m.submechanisms or []), (True, m.exoskeletons or [])]
        if m.submechanisms_file is not None:
            if m.submechanisms or m.exoskeletons:
                self.sink.error(m.key_span("submechanisms_file"), "E0315", "give either "
                                "'submechanisms_file' or 'submechanisms'/'exoskeletons', not both")
                return
            path = (self.lw.folder_of(m, "submechanisms_file") / m.submechanisms_file).resolve()
            if not path.is_file():
                self.sink.error(m.value_span("submechanisms_file"), "E0601",
                                f"submechanisms_file '{path}' does not exist")
            self.add(ops.SubmechanismsFile(span=m.value_span("submechanisms_file"), path=str(path)))
        for exo, items in lists:
            for s in items:
                joints = []
                for key in ("jointnames_independent", "jointnames_spanningtree", "jointnames_active",
                            "jointnames", "jointnames_dependent"):
                    joints += [j for j in getattr(s, key, []) if j not in joints]
                links = [b for lc in getattr(s, "loop_constraints", [])
                         for b in (lc.predecessor_body, lc.successor_body)]
                links += [s.around] if getattr(s, "around", None) else []
                self.add(ops.AddSubmechanism(span=s.span, name=s.name, exoskeleton=exo, joints=tuple(joints),
                                             links=tuple(dict.fromkeys(links)),
                                             definition=s.to_data()))
        if m.submechanisms or m.exoskeletons:
            span = m.key_span("submechanisms" if m.submechanisms else "exoskeletons")
            self.add(ops.CompleteSubmechanisms(span=span))

    def sensors(self) -> None:
        assert self.model.sensors is not None
        for kind, d in sensor_entries(self.model.sensors):
            if kind and d.type and d.type != kind:
                self.sink.error(d.value_span("type"), "E0316", f"sensor '{d.name}' is listed under "
                                f"{kind} but says type {d.type}")
                continue
            kind = kind or d.type
            if kind is None:
                self.sink.error(d.span, "E0316", f"sensor '{d.name}' has no 'type'")
                continue
            if kind in SINGLE_LINK_SENSORS and d.link is None and d.joint is None:
                self.sink.error(d.span, "E0316", f"{kind} sensor '{d.name}' needs a 'link'")
                continue
            if kind in MULTI_LINK_SENSORS and not d.targets:
                self.sink.error(d.span, "E0316", f"{kind} sensor '{d.name}' needs 'targets' "
                                "(a list, or All)")
                continue
            self.add(ops.AddSensor(
                span=d.span, type=kind, name=d.name, link=d.link, joint=d.joint, frame=d.frame,
                targets=tuple(d.targets or ()), targets_kind="link" if kind.startswith("Node") else "joint",
                position_offset=self.lw.vec(d, "position_offset", f"sensor '{d.name}' position_offset"),
                orientation_offset=self.lw.vec(d, "orientation_offset", f"sensor '{d.name}' orientation"),
                annotations=d.entries, spans=_spans(d, "link", "joint", "frame", "targets")))


# Keys that belong to a new frame's joint, and mean nothing on an existing link.
_NEW_FRAME_ONLY = ("parent", "jointname", "xyz", "rpy", "axis", "type", "mass", "joint")
# Keys that act on one link, and mean nothing in frames' $default.
_NOT_IN_FRAME_DEFAULT = ("transform_link", "transform_frame", "reparent_to", "make_root", "name_editing",
                         *_NEW_FRAME_ONLY)
# Keys that act on one joint, and mean nothing in joints' $default.
_NOT_IN_JOINT_DEFAULT = ("type", "axis", "remove", "cut_joint", "parent", "child", "constraint_axes",
                         "move_joint_axis_to_intersection", "mimic", "movement_depends_on", "active",
                         "motor", "name_editing")
