"""URDF elements mpc does not model → ir Fragment: the element as lxml serialises it (less the
namespace declarations <robot> makes, dedented) and the link and joint names it mentions.

It reads no meaning into a fragment: `<gazebo>`, `<transmission>`, `<ros2_control>`, vendor
tags and unknown children of links and joints travel as text (backends/urdf_reader.py).
"""

from __future__ import annotations

from collections.abc import Callable

from lxml import etree

from mpc.backends.xml import XmlSource
from mpc.ir.fragments import Fragment, FragmentRef, RefKind, lazy_fragment


class Fragments:
    """The fragments of one URDF file, made as the reader meets them.

    names: every link and joint name of the file (`link_names`, `joint_names`: each kind;
    `both`: those of a link and a joint), set before the first fragment is made and never
    changed after (a fragment's references are found when first asked for). make_ref: the
    maker of FragmentRef (core/record.py maker).
    """

    def __init__(self, src: XmlSource, make_ref: Callable[..., FragmentRef]) -> None:
        self.src, self.make_ref = src, make_ref
        self.link_names: set[str] = set()
        self.joint_names: set[str] = set()
        self.names: set[str] = set()
        self.both: set[str] = set()  # the names of a link and of a joint (kind_of decides)
        # What tostring adds to a fragment's start tag for the namespaces <robot> declares,
        # each and (as it writes them, right after the tag's name) all together. When only
        # <robot> declares any, those no element uses are dropped from the tree first: tostring
        # would copy each into every fragment (all four of TALOS's), to be cut out again.
        self.nsmap = src.root.nsmap  # as the file wrote it, for the robot's attributes
        if self.nsmap and src.text.count("xmlns") == len(self.nsmap):
            etree.cleanup_namespaces(src.root)
        self.namespace_declarations = [f' xmlns{":" + prefix if prefix else ""}="{uri}"'
                                       for prefix, uri in src.root.nsmap.items()]
        self.declared = "".join(self.namespace_declarations)
        # Whether the text between elements is the text as written (no character reference or
        # CDATA section could stand in an element's indentation): `indentation` may read it.
        self.plain = "&" not in src.text and not _has_cdata(src.text)

    def fragment(self, el: etree._Element, comments: tuple[str, ...] = ()) -> Fragment:
        """The fragment of `el`, its references found when first asked for: only a rename or a
        cut asks (ir/fragments.py: LazyFragment)."""
        tag = el.tag
        xml = etree.tostring(el, encoding="unicode", with_tail=False)
        if self.declared:
            # tostring re-declares every namespace in scope; <robot> declares them already.
            cut = len(tag) + 1 if tag[0] != "{" else xml.find(" ")
            if xml.startswith(self.declared, cut) and xml.find(">", 0, cut) < 0:
                xml = xml[:cut] + xml[cut + len(self.declared):]
            else:  # declared in another order, or among declarations of its own
                head_end = xml.find(">")
                head = xml[:head_end]
                for declaration in self.namespace_declarations:
                    head = head.replace(declaration, "", 1)
                xml = head + xml[head_end:]
        indentation = self.indentation(el)
        if indentation:  # its lines less the indentation of its first
            xml = xml.replace("\n" + " " * indentation, "\n")
        return lazy_fragment(tag, xml, comments, self.src.lazy_span(el), self, el)

    def indentation(self, el: etree._Element) -> int:
        """The column of `el`'s start tag less one: the length of the text before it on its
        line. That text ends the text before the element (the tail of the node before it, or its
        parent's text) when a line break stands there: looking it up in the file (XmlSource.span)
        costs more than the rest of a fragment."""
        previous = el.getprevious()
        before = previous.tail if previous is not None else el.getparent().text
        if before and self.plain:
            line_break = before.rfind("\n")
            if line_break >= 0 and before[line_break + 1:].strip(" \t") == "":
                return len(before) - line_break - 1
        return self.src.span(el).col - 1

    def refs(self, el: etree._Element) -> tuple[FragmentRef, ...]:
        """Every attribute or text in the fragment that equals a link or joint name, in
        document order (each element's attributes, then its text)."""
        out: list[FragmentRef] = []
        names, both, links, make_ref = self.names, self.both, self.link_names, self.make_ref
        for node in el.iter(etree.Element):
            items = node.items()
            if items:
                for attr, value in items:
                    if (name := value.strip()) in names:
                        kind = (self.kind_of(name, node.tag + attr) if name in both
                                else "link" if name in links else "joint")
                        out.append(make_ref(() if node is el else _path(el, node), attr, kind, name))
            text = node.text
            if text and (name := text.strip()) and name in names:
                kind = self.kind_of(name, node.tag) if name in both else "link" if name in links else "joint"
                out.append(make_ref(() if node is el else _path(el, node), None, kind, name))
        return tuple(out) if out else ()

    def kind_of(self, name: str, hint: str) -> RefKind:
        """Whether the known `name` is a link's or a joint's; `hint` (where it stands) decides
        for a name that is both."""
        is_link, is_joint = name in self.link_names, name in self.joint_names
        if is_link and is_joint:
            return "joint" if "joint" in hint.lower() else "link"
        return "link" if is_link else "joint"


def _has_cdata(text: str) -> bool:
    """Whether `text` holds a CDATA section: each `[` looked at (a search for "<![CDATA["
    itself takes 60 µs in TALOS's text, one for "[" a microsecond)."""
    i = text.find("[")
    while i >= 0:
        if i >= 2 and text.startswith("<![CDATA[", i - 2):
            return True
        i = text.find("[", i + 1)
    return False


def _path(root: etree._Element, node: etree._Element) -> tuple[int, ...]:
    """The child indices (comments counted) from `root` down to its descendant `node`."""
    if node is root:  # most names stand in a fragment's own attributes
        return ()
    path: list[int] = []
    while node is not root:
        parent = node.getparent()
        path.append(parent.index(node))
        node = parent
    return tuple(reversed(path))
