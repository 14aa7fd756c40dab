"""Rename links, joints, collisions and visuals of a Robot, and every reference to them.

References that follow a rename: joint parents and children, mimic targets, the root,
the names opaque fragments record (gazebo references, transmission joints, plugin
parameters), and what the SMURF writes (motors, sensors, poses, loop joints,
submechanisms, dependencies, self-collision pairs). Rename maps need not be complete: absent names stay.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

from lxml import etree

from mpc.ir.fragments import Fragment, FragmentRef
from mpc.ir.robot import Joint, Link, Robot
from mpc.ir.span import hardened_parser

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
    renamed = replace(robot, links=links, joints=joints, root=link(robot.root),
                      fragments=frags(robot.fragments))
    return _follow_extras(robot, renamed, link, joint)


def _follow_extras(old: Robot, robot: Robot, link: Rename, joint: Rename) -> Robot:
    """`robot` whose motors, sensors, poses, loop joints, submechanisms, joint dependencies
    and self-collision pairs name the renamed links and joints (the SMURF writes them).
    Free annotation categories are data mpc does not interpret, and are left as they are."""
    def either(name: str) -> str:
        return joint(name) if name in old.joints else link(name)

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
        motors={n: replace(m, joint=joint(m.joint)) for n, m in robot.motors.items()},
        sensors={n: replace(s, link=s.link and link(s.link), joint=s.joint and joint(s.joint),
                            frame=s.frame and link(s.frame), targets=tuple(map(either, s.targets)))
                 for n, s in robot.sensors.items()},
        poses={n: {joint(j): v for j, v in p.items()} for n, p in robot.poses.items()},
        cut_joints={n: replace(c, parent=link(c.parent), child=link(c.child))
                    for n, c in robot.cut_joints.items()},
        submechanisms=tuple(replace(sm, definition=submechanism(sm.definition))
                            for sm in robot.submechanisms))


def rename_with(mapping: Mapping[str, str]) -> Rename:
    return lambda name: mapping.get(name, name)

