"""Rename links, joints, collisions and visuals of a Robot, and every reference to them.

References that follow a rename: every field typed as a reference (ir/refs.py: joint parents
and children, mimic targets, the root, motors, sensors, poses, loop joints), the names opaque
fragments record (gazebo references, transmission joints, plugin parameters), and the free data
the SMURF writes (submechanisms, dependencies, self-collision pairs). Rename maps need not be
complete: absent names stay.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

from lxml import etree

from mpc.core.span import hardened_parser
from mpc.ir import refs as declared
from mpc.ir.fragments import Fragment, FragmentRef
from mpc.ir.robot import Joint, Link, Robot

Rename = Callable[[str], str]


def _same(name: str) -> str:
    return name


def xmlns_of(robot: Robot) -> str:
    """The namespace declarations of `<robot>`, which fragments may use."""
    return "".join(f' {k}="{v}"' for k, v in robot.extra_attrs if k.startswith("xmlns"))


def rename_fragment(frag: Fragment, link: Rename, joint: Rename, xmlns: str = "") -> Fragment:
    """The fragment with every recorded reference renamed."""
    renamed = [(ref, (link if ref.kind == "link" else joint)(ref.name)) for ref in frag.refs]
    if all(new == ref.name for ref, new in renamed):
        return frag
    # Parse inside a wrapper that declares the robot's namespaces, which the fragment may use.
    wrapper = etree.fromstring(f"<w{xmlns}>{frag.xml}</w>", hardened_parser())
    root = wrapper[0]
    refs = []
    for ref, new in renamed:
        el = root
        for i in ref.path:
            el = el[i]
        if ref.attr is None:
            el.text = (el.text or "").replace(ref.name, new)
        else:
            el.set(ref.attr, el.get(ref.attr, "").replace(ref.name, new))
        refs.append(FragmentRef(ref.path, ref.attr, ref.kind, new))
    xml = etree.tostring(root, encoding="unicode", with_tail=False)
    head_end = xml.find(">")
    head = xml[:head_end]
    for decl in xmlns.split():
        head = head.replace(" " + decl, "", 1)
    return replace(frag, xml=head + xml[head_end:], refs=tuple(refs))


def rename_robot(robot: Robot, link: Rename = _same, joint: Rename = _same,
                 collision: Rename = _same, visual: Rename = _same) -> Robot:
    """`robot` with names mapped; the caller guarantees the maps create no duplicates.

    Every field typed as a reference (ir/refs.py) follows: joint ends, mimics, the root, motors,
    sensors, loop joints, poses. XML fragments and free data (submechanism definitions,
    annotations) declare nothing and are renamed here by what they are known to hold."""
    xmlns = xmlns_of(robot)
    by_kind = {"link": link, "joint": joint, "collision": collision, "visual": visual}

    def rename(kinds: tuple[str, ...], name: str) -> str:
        kind = kinds[0] if len(kinds) == 1 or name in robot.joints else kinds[-1]  # joint, else link
        return by_kind.get(kind, _same)(name)

    def frags(items: tuple[Fragment, ...]) -> tuple[Fragment, ...]:
        return tuple(rename_fragment(f, link, joint, xmlns) for f in items)

    def shapes(items: tuple) -> tuple:
        return tuple(replace(s, extras=frags(s.extras)) for s in items)

    links: dict[str, Link] = {}
    for name, item in robot.links.items():
        links[link(name)] = declared.renamed(replace(
            item, extras=frags(item.extras), visuals=shapes(item.visuals),
            collisions=shapes(item.collisions)), rename)
    joints: dict[str, Joint] = {
        joint(name): declared.renamed(replace(item, extras=frags(item.extras)), rename)
        for name, item in robot.joints.items()}
    renamed = declared.renamed(replace(robot, links=links, joints=joints, fragments=frags(robot.fragments)),
                               rename, only=("root", "motors", "sensors", "cut_joints", "poses"))
    return _follow_free_data(renamed, link, joint)


def _follow_free_data(robot: Robot, link: Rename, joint: Rename) -> Robot:
    """`robot` whose submechanisms, joint dependencies and self-collision pairs, free data as
    written in the definition, name the renamed links and joints (the SMURF writes them).
    Free annotation categories are data mpc does not interpret, and are left as they are."""

    def submechanism(definition: Mapping[str, object]) -> dict[str, object]:
        out = dict(definition)
        for key, value in definition.items():
            if key.startswith("jointnames") and isinstance(value, list | tuple):
                out[key] = [joint(j) if isinstance(j, str) else j for j in value]
            elif key == "around" and isinstance(value, str):
                out[key] = link(value)
            elif key == "loop_constraints" and isinstance(value, list | tuple):
                out[key] = [{k: link(v) if k.endswith("_body") and isinstance(v, str) else v
                             for k, v in c.items()} if isinstance(c, Mapping) else c for c in value]
        return out

    def depends(j: Joint) -> Joint:
        deps = j.annotations.get("movement_depends_on")
        if not isinstance(deps, list | tuple):
            return j
        new = [{**d, "joint_name": joint(d["joint_name"])} if isinstance(d, Mapping) and
               isinstance(d.get("joint_name"), str) else d for d in deps]
        return replace(j, annotations={**j.annotations, "movement_depends_on": new})

    annotations = dict(robot.annotations)
    pairs = annotations.get("self_collision", {}).get("may_collide")
    if isinstance(pairs, list | tuple):
        annotations["self_collision"] = {**annotations["self_collision"], "may_collide": [
            [link(n) if isinstance(n, str) else n for n in p] if isinstance(p, list | tuple) else p
            for p in pairs]}
    return replace(
        robot, joints={n: depends(j) for n, j in robot.joints.items()}, annotations=annotations,
        submechanisms=tuple(replace(sm, definition=submechanism(sm.definition))
                            for sm in robot.submechanisms))


def rename_with(mapping: Mapping[str, str]) -> Rename:
    return lambda name: mapping.get(name, name)

