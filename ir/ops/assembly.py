"""Assembly ops: load an input into a part, edit its names, cut it, mirror it, attach it.

A definition's `assemble` tree becomes parts named by their place in the tree
(`root`, `root/0`, `root/0/1`, …). Each part is loaded from an input model, edited,
and attached to its parent part; after the last attach only `root` remains.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any, Literal

from mpc.core.diagnostics import did_you_mean
from mpc.core.record import record
from mpc.ir import refs as declared
from mpc.ir.names import Names
from mpc.ir.naming import LINK_SUFFIX, NameRule, edit_name, takes_link_suffix, without_link_suffix
from mpc.ir.ops.base import Effects, Op, Phase, Ref
from mpc.ir.refs import JointName, LinkRef
from mpc.ir.rename import rename_robot, rename_with
from mpc.ir.robot import IDENTITY, Joint, Limit, Pose, Robot

Vec3 = tuple[float, float, float]


@record(kw_only=True)
class LoadModel(Op):
    """Start part `part` from input model `input` (the driver reads it)."""

    PHASE = Phase.LOAD

    input: str


_SECTION_OF_KIND = {"link": Phase.FRAMES, "joint": Phase.JOINTS, "collision": Phase.COLLISIONS,
                    "visual": Phase.VISUALS}


@record(kw_only=True)
class EditNames(Op):
    """Rename names of the part by `rules`.

    kinds: the kinds of names edited (all when empty): link, joint, collision, visual.
    only: the names edited (all when empty), of the one kind in `kinds`.
    joint_equals_link_name: each joint is named after its child link (after `rules`), minus a
        `_link` ending; the rules do not rename joints then.
    append_link_suffix: "ALWAYS" or "NAME_DUPLICATES" (ir/naming.py `takes_link_suffix`),
        after the rest, so NAME_DUPLICATES sees the joints' new names.
    """

    PHASE = Phase.NAMES

    WHAT = "name_editing"

    rules: tuple[NameRule, ...]
    kinds: tuple[str, ...] = ()
    only: tuple[str, ...] = ()
    joint_equals_link_name: bool = False
    append_link_suffix: str = ""

    def phase(self) -> Phase:
        """An assembly entry's name_editing renames every kind; a section's renames one kind,
        in that section (`frames` links, `joints` joints…)."""
        if len(self.kinds) != 1:
            return Phase.NAMES
        return _SECTION_OF_KIND.get(self.kinds[0], Phase.NAMES)

    def _edit(self, kind: str):
        only = frozenset(self.only)
        if self.kinds and kind not in self.kinds:
            return lambda name: name
        return lambda name: name if only and name not in only else edit_name(name, kind, self.rules)

    def reads(self) -> tuple[Ref, ...]:
        kind = self.kinds[0] if len(self.kinds) == 1 else "link"
        return tuple(Ref(kind, n, "only") for n in self.only)  # type: ignore[arg-type]

    def maps(self, names: Names) -> dict[str, dict[str, str]]:
        """Old name → new name of every link and joint; the tree is needed by the flags."""
        link, joint = self._edit("link"), self._edit("joint")
        links = {n: link(n) for n in names.links}
        if self.joint_equals_link_name:
            joints = {j: without_link_suffix(links.get(c, c)) for j, (_, c) in names.joints.items()}
        else:
            joints = {j: joint(j) for j in names.joints}
        if self.append_link_suffix:
            above = {c: joints[j] for j, (_, c) in names.joints.items()}
            links = {old: new + LINK_SUFFIX if takes_link_suffix(new, self.append_link_suffix, above.get(old))
                     else new for old, new in links.items()}
        return {"link": links, "joint": joints}

    def effect(self, names: Names, effects: Effects) -> Names:
        maps = self.maps(names)
        for kind, mapping in maps.items():
            seen: dict[str, str] = {}
            for old, new in sorted(mapping.items()):
                if new in seen:
                    why = (f": joint_equals_link_name names them after their child links "
                           f"'{names.joints[seen[new]][1]}' and '{names.joints[old][1]}'"
                           if kind == "joint" and self.joint_equals_link_name else "")
                    effects.error("E0302", f"name editing gives two {kind}s the name '{new}' "
                                  f"('{seen[new]}' and '{old}'){why}")
                seen[new] = old
        link, joint = rename_with(maps["link"]), rename_with(maps["joint"])
        collision, visual = self._edit("collision"), self._edit("visual")
        return replace(
            names, links=frozenset(maps["link"].values()), root=link(names.root),
            joints={joint(j): (link(p), link(c)) for j, (p, c) in names.joints.items()},
            collisions={link(k): frozenset(map(collision, v)) for k, v in names.collisions.items()},
            visuals={link(k): frozenset(map(visual, v)) for k, v in names.visuals.items()},
        )

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        if not self.joint_equals_link_name and not self.append_link_suffix:
            return rename_robot(robot, self._edit("link"), self._edit("joint"),
                                self._edit("collision"), self._edit("visual"))
        maps = self.maps(Names.of(robot))
        return rename_robot(robot, rename_with(maps["link"]), rename_with(maps["joint"]),
                            self._edit("collision"), self._edit("visual"))


@record(kw_only=True)
class RemoveBeyond(Op):
    """Keep the links up to and including `links`; remove everything below them."""

    PHASE = Phase.REMOVE_BEYOND

    WHAT = "remove_beyond"

    links: tuple[LinkRef, ...]

    def _kept(self, names: Names) -> set[str]:
        below: set[str] = set()
        for link in self.links:
            below |= names.subtree(link) - {link}
        return set(names.links) - below

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.keep(self._kept(names), why=f"remove_beyond (line {self.span.line})")

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        return keep_links(robot, self._kept(Names.of(robot)), robot.root)


@record(kw_only=True)
class TakeLeaf(Op):
    """Keep the subtree rooted at `link`; it becomes the root."""

    PHASE = Phase.TAKE_LEAF

    WHAT = "take_leaf"

    link: LinkRef

    def effect(self, names: Names, effects: Effects) -> Names:
        return names.keep(names.subtree(self.link), root=self.link,
                          why=f"take_leaf (line {self.span.line})")

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        return keep_links(robot, Names.of(robot).subtree(self.link), self.link)


def _named(kind: str, names: list[str], shown: int = 5) -> str:
    """`link 'a'`, or `3 links ('a', 'b', 'c')`, or `20 links ('a', …, 'e' and 15 more)`."""
    if len(names) == 1:
        return f"{kind} '{names[0]}'"
    listed = ", ".join(f"'{n}'" for n in names[:shown])
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return f"{len(names)} {kind}s ({listed}{more})"


def _as_written(name: str, written: str) -> str:
    return f"'{written}' ('{name}' after name editing)" if written and written != name else f"'{name}'"


def keep_links(robot: Robot, kept: set[str], root: str) -> Robot:
    """The robot cut down to `kept` links (a connected part of the tree containing `root`).

    Fragments that name a removed link or joint go with it.
    """
    joints = {n: j for n, j in robot.joints.items() if j.parent in kept and j.child in kept}
    gone_links = set(robot.links) - kept
    gone_joints = set(robot.joints) - set(joints)
    fragments = tuple(f for f in robot.fragments
                      if not (f.names("link") & gone_links or f.names("joint") & gone_joints))
    return replace(robot, root=root, links={n: lk for n, lk in robot.links.items() if n in kept},
                   joints=joints, fragments=fragments, **_extras_kept(robot, kept, set(joints)))


def _extras_kept(robot: Robot, links: set[str], joints: set[str]) -> dict[str, Any]:
    """Motors, sensors (by their link or joint), poses, loop joints and submechanisms that still
    name only what is kept (their references as ir/refs.py declares them)."""

    def kept(kind: str, name: str) -> bool:
        """Not one of the robot's links or joints that the cut leaves out."""
        if kind == "link":
            return name in links or name not in robot.links
        return kind != "joint" or name in joints or name not in robot.joints

    def only_kept(items: Mapping[str, Any], only: tuple[str, ...] = ()) -> dict[str, Any]:
        return {n: x for n, x in items.items() if declared.names_only(x, kept, robot.joints, only)}

    return {
        "motors": only_kept(robot.motors),
        "sensors": only_kept(robot.sensors, only=("link", "joint")),
        "poses": {n: {j: v for j, v in p.items() if j in joints} for n, p in robot.poses.items()},
        "cut_joints": only_kept(robot.cut_joints),
        "submechanisms": tuple(sm for sm in robot.submechanisms
                               if declared.names_only(sm, kept, robot.joints)),
    }


@record(kw_only=True)
class Mirror(Op):
    """Mirror the part at the plane through its root with normal `plane`.

    flip_axis: the frame axis flipped afterwards so every frame stays right-handed.
    exclude_meshes: meshes used as they are (symmetric ones), or ("ALL",).
    name_replacements: (pattern, replacement) pairs applied to every name.
    """

    PHASE = Phase.MIRROR

    plane: Vec3 = (0.0, 1.0, 0.0)
    flip_axis: Literal[0, 1, 2] = 1
    exclude_meshes: tuple[str, ...] = ()
    name_replacements: tuple[tuple[str, str], ...] = ()

    def effect(self, names: Names, effects: Effects) -> Names:
        if not self.name_replacements:
            return names
        rule = (NameRule(replacements=self.name_replacements),)
        return EditNames(span=self.span, part=self.part, rules=rule).effect(names, effects)

    def apply(self, robot: Robot, effects: Effects) -> Robot:
        from mpc.ir.mirror import mirror_robot  # numpy: not on the path of `mpc check`

        mirrored = mirror_robot(robot, self.plane, self.flip_axis, self.exclude_meshes)
        if not self.name_replacements:
            return mirrored
        rule = (NameRule(replacements=self.name_replacements),)
        return EditNames(span=self.span, part=self.part, rules=rule).apply(mirrored, effects)


@record(kw_only=True)
class Attach(Op):
    """Attach part `child` to `part` with a new joint from link `parent` to link `child_link`.

    child_link: the child part's link the joint ends in (None: the child part's root).
    name: the joint's name (None: `<parent>2<child_link>`).
    origin: X_PJ, the joint frame in the parent link; None with `r2r` given.
    r2r: X_RpRc, the child model's root in the parent model's root (a 4×4 row list),
        computed from the input models as they were read (before any editing).
    parent_written, child_written: the link names as written, when name editing changed them.
    suffixed: the fields ("parent", "child_link") whose link's part had `append_link_suffix:
        NAME_DUPLICATES`, which may have appended `_Link` to it: which it did is known from the
        part's tree only (`resolved`).
    """

    PHASE = Phase.ATTACH

    WHAT = "the attaching joint's parent"

    child: str
    parent: LinkRef
    child_link: LinkRef | None = None
    parent_written: str = ""
    child_written: str = ""
    name: JointName | None = None
    type: str = "fixed"
    origin: Pose = IDENTITY
    r2r: tuple[tuple[float, ...], ...] | None = None
    axis: Vec3 | None = None
    limit: Limit | None = None
    suffixed: tuple[str, ...] = ()

    def reads(self) -> tuple[Ref, ...]:
        return (Ref("link", self.parent, "parent", self.parent_written),)

    def parts(self) -> tuple[str, ...]:
        return (self.part, self.child)

    def resolved(self, parent: Names, child: Names) -> Attach:
        """The op naming its links as NAME_DUPLICATES left them: `X_Link` for a link `X` that
        is no more, when the joint above `X_Link` is `X` (exactly the links it renamed)."""
        if not self.suffixed:
            return self
        changes: dict[str, str] = {}
        for field, names in (("parent", parent), ("child_link", child)):
            name = getattr(self, field) or (child.root if field == "child_link" else "")
            written = "parent_written" if field == "parent" else "child_written"
            above = {c: j for j, (_, c) in names.joints.items()}
            if field in self.suffixed and name not in names.links \
                    and above.get(name + LINK_SUFFIX) == name:
                changes[field] = name + LINK_SUFFIX
                changes[written] = getattr(self, written) or name
        return replace(self, suffixed=(), **changes)

    def joint_name(self, child_root: str) -> str:
        return self.name or f"{self.parent}2{self.child_link or child_root}"

    def merge(self, parent: Names, child: Names, effects: Effects, origins: tuple[str, str]) -> Names:
        """The names after attaching; a name in both parts is an error naming both."""
        child_link = self.child_link or child.root
        if child_link not in child.links:
            shown = _as_written(child_link, self.child_written)
            effects.error("E0303", f"attach: the child model has no link {shown}"
                          f"{did_you_mean(child_link, child.links)}", "child_link")
        elif child_link != child.root:  # the child model is re-rooted there (ir/reroot.py)
            from mpc.ir.reroot import reroot_names

            child = reroot_names(child, child_link)
        joint = self.joint_name(child.root)
        for kind, a, b in (("link", parent.links, child.links),
                           ("joint", frozenset(parent.joints), frozenset(child.joints))):
            twice = sorted(a & b)  # one mistake (a part not renamed) is one report, however many names
            if twice:
                effects.error("E0304", f"{_named(kind, twice)} would exist twice after attaching: in "
                              f"{origins[0]} and in {origins[1]}; rename one with name_editing")
        if joint in parent.joints or joint in child.joints:
            effects.error("E0304", f"the attaching joint '{joint}' would exist twice: a joint of "
                          f"that name is already in {origins[0] if joint in parent.joints else origins[1]}",
                          "name")
        return replace(
            parent, links=parent.links | child.links,
            joints={**child.joints, **parent.joints, joint: (self.parent, child_link)},
            collisions={**child.collisions, **parent.collisions},
            visuals={**child.visuals, **parent.visuals},
            materials=parent.materials | child.materials,
        )

    def attach(self, parent: Robot, child: Robot) -> Robot:
        """The parent robot with the child robot hung below `parent` (origin already resolved),
        re-rooted at `child_link` first (RerootError when it cannot be)."""
        child_link = self.child_link or child.root
        if child_link != child.root:
            from mpc.ir.reroot import reroot

            child = reroot(child, child_link)
        joint = Joint(name=self.joint_name(child.root), type=self.type,  # type: ignore[arg-type]
                      parent=self.parent, child=child_link, origin=self.origin, axis=self.axis,
                      limit=self.limit, span=self.span)
        materials = {**child.materials, **parent.materials}
        return replace(parent, links={**parent.links, **child.links},
                       joints={**parent.joints, **child.joints, joint.name: joint},
                       materials=materials, fragments=parent.fragments + child.fragments)


def r2r_origin(attach: Attach, parent_input: Robot, child_input: Robot) -> Pose:
    """X_PJ from a root-to-root transform: X_PJ = X_RpP⁻¹ · X_RpRc · X_RcC.

    X_RpP and X_RcC are the attach links in their input models as read, so the
    transform the user measured between the two roots is kept whatever the editing.
    """
    import numpy as np  # not at the top: `mpc check` never needs it

    from mpc.ir import transforms as tf
    from mpc.ir.kinematics import link_in_root, matrix_pose

    assert attach.r2r is not None
    X_RpRc = np.array(attach.r2r, dtype=float)
    # The inputs as read have the names as written (before name editing).
    X_RpP = link_in_root(parent_input, attach.parent_written or attach.parent)
    X_RcC = link_in_root(child_input, attach.child_written or attach.child_link or child_input.root)
    return matrix_pose(tf.compose(tf.inverse(X_RpP), X_RpRc, X_RcC))
