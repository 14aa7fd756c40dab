"""Rename links, joints, collisions and visuals of a Robot, and every reference to them.

References that follow a rename: every reference ir/refs.py declares (joint parents and
children, mimic targets, the root, motors, sensors, poses, loop joints, and the names in the
free data the SMURF writes: submechanisms, dependencies, self-collision pairs), and the names
opaque fragments record (gazebo references, transmission joints, plugin parameters). Rename
maps need not be complete: absent names stay.
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

    Every reference declared in ir/refs.py follows: joint ends, mimics, the root, motors,
    sensors, loop joints, poses, and the names in free data (submechanism definitions, joint
    dependencies, self-collision pairs: refs.FREE_DATA). XML fragments record their own."""
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
    return declared.renamed(replace(robot, links=links, joints=joints, fragments=frags(robot.fragments)),
                            rename, only=("root", "motors", "sensors", "cut_joints", "poses", "submechanisms",
                                          "annotations"))


def rename_with(mapping: Mapping[str, str]) -> Rename:
    return lambda name: mapping.get(name, name)

