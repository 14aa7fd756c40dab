"""`assemble` (AST) → the ops of the assembly: each part's steps, its children, their attaching.

A part's own steps (load, name editing, remove_beyond, take_leaf, mirror) come in the order of
their phases (ir/ops/base.py: Phase), then each child part depth first, each followed by the
`attach` that joins it to its parent (compiler/passes/order_ops.py holds the same order). It
reads no model: names in `joint:` are edited by the rules of their part, as written.
"""

from __future__ import annotations

from mpc.compiler.expr import evaluate
from mpc.compiler.lower_context import LowerContext, items_span
from mpc.compiler.schema.assembly import AssembleChild, AssemblyEntry, AttachJoint
from mpc.core.diagnostics import did_you_mean
from mpc.core.record import record
from mpc.ir.naming import LINK_SUFFIX, NameRule, edit_name, takes_link_suffix
from mpc.ir.ops import ROOT, Attach, EditNames, LoadModel, Mirror, Op, RemoveBeyond, TakeLeaf
from mpc.ir.program import Input
from mpc.ir.robot import Limit, Pose


@record
class _Part:
    """A lowered part of the assembly: its name rules and `append_link_suffix` (which the
    names of its attaching follow), and its ops with its children's."""

    name: str
    rules: tuple[NameRule, ...]
    link_suffix: str
    ops: tuple[Op, ...]

    def edited_link(self, written: str) -> str:
        """A link name as written in `joint:`, after this part's name editing; NAME_DUPLICATES's
        suffix depends on the tree: Attach.resolved adds it."""
        name = edit_name(written, "link", self.rules)
        if self.link_suffix == "ALWAYS" and takes_link_suffix(name, "ALWAYS", None):
            name += LINK_SUFFIX
        return name


def lower_assembly(ctx: LowerContext, inputs: dict[str, Input]) -> list[Op]:
    """The ops of the assembly tree, in the language's order; none after an unknown model."""
    root = _part(ctx, ctx.model.assemble, ROOT, inputs)
    return list(root.ops) if root is not None else []


def _part(ctx: LowerContext, node: AssemblyEntry, part: str, inputs: dict[str, Input]) -> _Part | None:
    if node.model not in inputs:
        ctx.sink.error(node.value_span("model"), "E0301",
                       f"model '{node.model}' in {node.SECTION} is not one of the input models "
                       f"({', '.join(sorted(inputs))}){did_you_mean(node.model, set(inputs))}")
        return None
    ops: list[Op] = [LoadModel(span=node.value_span("model"), part=part, input=node.model)]
    rules: tuple[NameRule, ...] = ()
    editing = node.name_editing
    if editing is not None:
        rules = ctx.name_rules(editing)
        if rules or editing.joint_equals_link_name or editing.append_link_suffix:
            ops.append(EditNames(span=editing.span, part=part, rules=rules,
                                 joint_equals_link_name=editing.joint_equals_link_name,
                                 append_link_suffix=editing.append_link_suffix or ""))
        if editing.joint_equals_link_name:
            for key in ("joint_prefix", "joint_suffix", "joint_replacements"):
                if getattr(editing, key):
                    ctx.sink.warning(editing.key_span(key), "W0550", f"'{key}' has no effect: "
                                     "joint_equals_link_name names every joint after its child link",
                                     hint="edit the link names instead; the joints follow them")
    if node.remove_beyond is not None:
        spans = {f"links/{i}": items_span(node, "remove_beyond", i) for i in range(len(node.remove_beyond))}
        ops.append(RemoveBeyond(span=node.value_span("remove_beyond"), part=part, spans=spans,
                                links=tuple(node.remove_beyond)))
    if node.take_leaf is not None:
        ops.append(TakeLeaf(span=node.value_span("take_leaf"), part=part, link=node.take_leaf))
    if node.mirror is not None:
        m = node.mirror
        plane = ctx.vec(m, "plane", "mirror plane")
        ops.append(Mirror(span=m.span, part=part, plane=plane or (0.0, 1.0, 0.0),
                          flip_axis=m.flip_axis, exclude_meshes=tuple(m.exclude_meshes),
                          name_replacements=ctx.replacements(m, "name_replacements")))
    me = _Part(part, rules, (editing.append_link_suffix or "") if editing is not None else "", ())
    for i, node_child in enumerate(node.children):
        child = _part(ctx, node_child, f"{part}/{i}", inputs)
        if child is None:
            continue
        ops.extend(child.ops)
        attach = _attach(ctx, node_child, me, child)
        if attach is not None:
            ops.append(attach)
    return _Part(part, me.rules, me.link_suffix, tuple(ops))


def _attach(ctx: LowerContext, node: AssembleChild, parent: _Part, child: _Part) -> Attach | None:
    j: AttachJoint = node.joint
    what = f"joint of '{node.model}'"
    # Names in `joint:` are written as they are before each model's name editing.
    parent_link = parent.edited_link(j.parent)
    child_link = child.edited_link(j.child) if j.child else None
    suffixed = tuple(field for field, p in (("parent", parent), ("child_link", child))
                     if p.link_suffix == "NAME_DUPLICATES")
    r2r = None
    if j.r2r_transform is not None:
        rows = [[evaluate(v, j.value_span("r2r_transform"), ctx.sink, what=f"{what} r2r_transform")
                 for v in row] for row in j.r2r_transform]
        if any(v is None for row in rows for v in row):
            return None
        r2r = tuple(tuple(row) for row in rows)
        if j.xyz is not None or j.rpy is not None:
            ctx.sink.error(j.key_span("r2r_transform"), "E0306",
                           f"{what}: give either r2r_transform or xyz/rpy, not both")
    xyz = ctx.vec(j, "xyz", f"{what} xyz") or (0.0, 0.0, 0.0)
    rpy = ctx.vec(j, "rpy", f"{what} rpy") or (0.0, 0.0, 0.0)
    limit = None
    values = {k: ctx.num(j, k, f"{what} {k}") for k in ("min", "max", "eff", "vel")}
    if any(v is not None for v in values.values()):
        limit = Limit(lower=values["min"], upper=values["max"], effort=values["eff"],
                      velocity=values["vel"])
    missing = [k for k in ("eff", "vel") if values[k] is None and k not in j.given]
    if j.type in ("revolute", "prismatic") and missing:
        name = j.name or (f"{parent_link}2{child_link}" if child_link else None)
        joint = f"joint '{name}' attaching '{node.model}'" if name else \
            f"the joint attaching '{node.model}' to '{j.parent}'"
        ctx.sink.error(j.key_span("type"), "E0307",
                       f"{joint} is {j.type} but has no {' and '.join(f'{k!r}' for k in missing)}"
                       "; URDF needs both 'eff' and 'vel' (Phobos silently used 0)")
    spans = {"parent": j.value_span("parent"), "child_link": j.value_span("child"),
             "name": j.value_span("name")}
    return Attach(
        span=j.span, part=parent.name, spans=spans, child=child.name, parent=parent_link,
        child_link=child_link, name=j.name, type=j.type,
        parent_written=j.parent if parent_link != j.parent else "",
        child_written=j.child if j.child and child_link != j.child else "",
        origin=Pose(xyz, rpy), r2r=r2r,  # type: ignore[arg-type]
        axis=ctx.vec(j, "axis", f"{what} axis"), limit=limit,  # type: ignore[arg-type]
        suffixed=suffixed,
    )
