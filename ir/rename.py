"""Rename links, joints, collisions and visuals of a Robot, and every reference to them.

References that follow a rename: joint parents and children, mimic targets, the root,
and the names opaque fragments record (gazebo references, transmission joints,
plugin parameters). Rename maps need not be complete: absent names stay.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

from lxml import etree

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
    wrapper = etree.fromstring(f"<w{xmlns}>{frag.xml}</w>")
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
    """`robot` with names mapped; the caller guarantees the maps create no duplicates."""
    xmlns = xmlns_of(robot)

    def frags(items: tuple[Fragment, ...]) -> tuple[Fragment, ...]:
        return tuple(rename_fragment(f, link, joint, xmlns) for f in items)

    def shapes(items: tuple, rename: Rename) -> tuple:
        return tuple(replace(s, name=rename(s.name) if s.name else s.name, extras=frags(s.extras))
                     for s in items)

    links: dict[str, Link] = {}
    for name, item in robot.links.items():
        new = link(name)
        links[new] = replace(item, name=new, extras=frags(item.extras),
                             visuals=shapes(item.visuals, visual),
                             collisions=shapes(item.collisions, collision))
    joints: dict[str, Joint] = {}
    for name, item in robot.joints.items():
        new = joint(name)
        mimic = item.mimic and replace(item.mimic, joint=joint(item.mimic.joint))
        joints[new] = replace(item, name=new, parent=link(item.parent), child=link(item.child),
                              mimic=mimic, extras=frags(item.extras))
    return replace(robot, links=links, joints=joints, root=link(robot.root),
                   fragments=frags(robot.fragments))


def rename_with(mapping: Mapping[str, str]) -> Rename:
    return lambda name: mapping.get(name, name)

