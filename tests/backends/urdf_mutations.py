"""Seeded mutations of URDF text: a well-formed model → a variant that is broken, hostile or
only written differently, for the recorded reader and writer outputs (test_reader_golden.py,
test_writer_golden.py).

Tree mutations (delete, duplicate, move, rename elements; remove, add or spoil attributes)
break the model; text mutations (tags several to a line or over several lines, quotes, CRLF,
tabs, a BOM, non-ASCII text, namespaces, DOCTYPE, entities, CDATA, comments and processing
instructions anywhere, truncation) change how the same XML is written, or break the XML.
What it does not do: produce XML that is well-formed more often than by chance.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable

from lxml import etree

Mutation = Callable[[random.Random, bytes], bytes]

_TAGS = ("link", "joint", "visual", "collision", "inertial", "origin", "geometry", "mesh", "box",
         "cylinder", "sphere", "material", "color", "texture", "mass", "inertia", "parent",
         "child", "axis", "limit", "dynamics", "mimic", "calibration", "safety_controller",
         "gazebo", "transmission", "plugin", "capsule", "robot", "xacro:macro", "sensor")
_ATTRS = ("name", "type", "xyz", "rpy", "link", "filename", "scale", "size", "radius", "length",
          "value", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "lower", "upper", "effort",
          "velocity", "damping", "friction", "joint", "multiplier", "offset", "rgba", "reference",
          "k_velocity", "k_position", "soft_lower_limit", "soft_upper_limit", "rising",
          "falling", "reference_position", "extra", "xmlns:foo")
_VALUES = ("", " ", "abc", "1_0", "nan", "inf", "-inf", "1 2", "1 2 3 4", " 1 ", "-0", "1e400",
           "0x1", "1,2,3", "0 0 0", "1 0 0", "0.5", "  0\t0\n1 ", "revolute", "prismatic",
           "continuous", "fixed", "floating", "planar", "spherical", "Revolute", "a&b<c>\"d'",
           "é", "名前", "\u00a0", "package://nonexistent/mesh.stl", "/proc/self/environ",
           "file:///etc/passwd", "../../../../../../etc/passwd", "../meshes/x.stl", "meshes/",
           "file:///dev/zero", "package://example-robot-data/robots/../../../../etc/passwd",
           "/tmp", "${name}", "1 1 1 1", "0.1 0.2 0.3")
_CHUNKS = ("<!-- a comment -->", "<!-- <link name=\"x\"/> -->", "<?pi some data?>",
           "<![CDATA[ <joint> & ]]>", "text", "&amp;", "&#10;", "&lt;link&gt;", "é", "\t",
           "<!---->", "<!-- é <b>\n</b> -->", "<x:y xmlns:x=\"u\"/>", "<plain/>", "<:odd/>")


def _elements(root: etree._Element) -> list[etree._Element]:
    return [e for e in root.iter() if isinstance(e.tag, str)]


def _names(root: etree._Element) -> list[str]:
    return [e.get("name") for e in root if isinstance(e.tag, str) and e.get("name")] or ["x"]


def _tree(mutate: Callable[[random.Random, etree._Element], None]) -> Mutation:
    """A mutation of the parsed tree, serialised again (the text's layout is lxml's then)."""

    def apply(rng: random.Random, data: bytes) -> bytes:
        try:
            root = etree.fromstring(data, etree.XMLParser(resolve_entities=False))
        except etree.XMLSyntaxError:
            return data
        mutate(rng, root)
        return etree.tostring(root, xml_declaration=rng.random() < 0.5, encoding="utf-8")

    return apply


def _delete(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    if el.getparent() is not None:
        el.getparent().remove(el)


def _duplicate(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    if el.getparent() is not None:
        el.addnext(etree.fromstring(etree.tostring(el)))


def _move(rng: random.Random, root: etree._Element) -> None:
    els = _elements(root)
    el, target = rng.choice(els), rng.choice(els)
    if el.getparent() is not None and el not in target.iterancestors() and el is not target:
        target.insert(rng.randrange(len(target) + 1), el)


def _rename(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    tag = rng.choice(_TAGS)
    el.tag = tag.split(":")[-1] if el is root and rng.random() < 0.8 else tag.replace(":", "_")


def _drop_attr(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice([e for e in _elements(root) if e.attrib] or [root])
    if el.attrib:
        del el.attrib[rng.choice(list(el.attrib))]


def _spoil_attr(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    keys = list(el.attrib)
    attr = rng.choice(keys) if keys and rng.random() < 0.7 else rng.choice(_ATTRS)
    if attr.startswith("xmlns"):
        return
    value = rng.choice(_VALUES + tuple(_names(root)) * 2)
    el.set(attr, value)


def _mesh_path(rng: random.Random, root: etree._Element) -> None:
    """A mesh filename that leaves the package, names a special file or no file."""
    meshes = list(root.iter("mesh"))
    if meshes:
        rng.choice(meshes).set("filename", rng.choice([v for v in _VALUES if "/" in v]))


def _text(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    names = _names(root)
    el.text = rng.choice([*names, f" {rng.choice(names)} ", "text", "é", "1 2 3"])


def _insert(rng: random.Random, root: etree._Element) -> None:
    el = rng.choice(_elements(root))
    kind = rng.randrange(4)
    new = (etree.Comment(rng.choice([" c ", "é", " <link> "])) if kind == 0 else
           etree.ProcessingInstruction("pi", "data") if kind == 1 else
           etree.Element(rng.choice(_TAGS).replace(":", "_"),
                         {rng.choice(_ATTRS[:20]): rng.choice(_VALUES)}))
    if kind == 3:
        new = etree.fromstring(f'<link name="{rng.choice(_names(root))}"/>')
    el.insert(rng.randrange(len(el) + 1), new)


def _one_line(rng: random.Random, data: bytes) -> bytes:
    """Some tags several to a line: `>` and the next `<` joined."""
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    n = rng.randrange(2, 8)
    return b"\n".join([*lines[:i], b"".join(ln.strip() for ln in lines[i:i + n]), *lines[i + n:]])


def _many_lines(rng: random.Random, data: bytes) -> bytes:
    """Start tags over several lines: the space before some attributes becomes a line break."""
    spots = [m.start() for m in re.finditer(rb' [\w:]+=["\']', data)]
    for spot in sorted(rng.sample(spots, min(len(spots), rng.randrange(1, 20))), reverse=True):
        data = data[:spot] + rng.choice([b"\n", b"\n    ", b"\n\t", b" \n"]) + data[spot + 1:]
    if rng.random() < 0.3:  # the `>` or `/>` of some start tags on a line of its own
        data = re.sub(rb'"(/?>)', lambda m: b'"\n' + m.group(1) if rng.random() < 0.2 else m.group(0), data)
    return data


def _quotes(rng: random.Random, data: bytes) -> bytes:
    return re.sub(rb'="([^"\']*)"',
                  lambda m: b"='" + m.group(1) + b"'" if rng.random() < 0.5 else m.group(0), data)


def _spaces(rng: random.Random, data: bytes) -> bytes:
    """Unusual but legal whitespace: around `=`, before `/>`, tabs, in end tags."""
    choice = rng.randrange(4)
    if choice == 0:
        return re.sub(rb'(\w)="', lambda m: m.group(1) + rng.choice([b' = "', b'=\t"', b' ="']), data,
                      count=rng.randrange(1, 50))
    if choice == 1:
        return data.replace(b"/>", b" />", rng.randrange(1, 50))
    if choice == 2:
        return data.replace(b"  ", b"\t")
    return re.sub(rb"</(\w+)>", rb"</\1 >", data, count=rng.randrange(1, 50))


def _crlf(rng: random.Random, data: bytes) -> bytes:
    return data.replace(b"\n", rng.choice([b"\r\n", b"\r", b"\n\r"]))


def _chunk(rng: random.Random, data: bytes) -> bytes:
    """A comment, PI, CDATA, text, entity or odd tag anywhere between `>` and `<`."""
    spots = [m.end() for m in re.finditer(rb">", data)] or [0]
    spot = rng.choice(spots)
    return data[:spot] + rng.choice(_CHUNKS).encode() + data[spot:]


def _prolog(rng: random.Random, data: bytes) -> bytes:
    """Something before the root: a BOM, a DOCTYPE (with entities), another declaration."""
    body = re.sub(rb"^<\?xml[^>]*\?>\s*", b"", data)
    head = rng.choice([
        b"\xef\xbb\xbf", b'<?xml version="1.0" encoding="ISO-8859-1"?>\n',
        b'<!DOCTYPE robot>\n', b'<!DOCTYPE robot [<!ENTITY e "<link name=\'e\'/>">]>\n',
        b'<!DOCTYPE robot SYSTEM "http://example.com/x.dtd">\n', b"<!-- head -->\n",
        b'<?xml version="1.0" encoding="utf-16"?>\n', b'<?xml version="1.1"?>\n',
        b'<!DOCTYPE robot [<!ENTITY big "aaaaaaaaaa"><!ELEMENT robot ANY>]>\n',
        b'<!DOCTYPE robot [<!ELEMENT robot ANY><!ENTITY tag "<link name=\'e\'/>">]>\n',
        b'<?xml version="1.0" encoding="UTF-7"?>\n'])
    data = head + body
    if b"ENTITY" in head and rng.random() < 0.7:
        data = _chunk(rng, data).replace(b"&amp;", b"&e;").replace(b"&#10;", b"&big;")
    return data


def _namespaces(rng: random.Random, data: bytes) -> bytes:
    """Namespace declarations on <robot> or below (used or not), prefixed tags and attributes."""
    choice = rng.randrange(5)
    if choice == 4:
        return re.sub(rb"<(robot|link|joint|gazebo|transmission|plugin) ", lambda m: m.group(0) + (
            b'xmlns:unused="urn:unused" ' if rng.random() < 0.3 else b""), data)
    if choice == 0:
        return data.replace(b"<robot ", b'<robot xmlns:xacro="http://ros.org/wiki/xacro" ', 1).replace(
            b"<gazebo", b"<xacro:gazebo", 1).replace(b"</gazebo>", b"</xacro:gazebo>", 1)
    if choice == 1:
        return data.replace(b"<robot ", b'<robot xmlns="http://example.com/urdf" ', 1)
    if choice == 2:
        return re.sub(rb"<(link|joint|visual) ", lambda m: m.group(0) + b'xmlns:q="urn:q" q:a="1" '
                      if rng.random() < 0.3 else m.group(0), data)
    return data.replace(b"<mesh ", b"<u:mesh ", 1)  # an undeclared prefix


def _non_ascii(rng: random.Random, data: bytes) -> bytes:
    spots = [m.end() for m in re.finditer(rb'(name="|<!--|>)', data)] or [0]
    spot = rng.choice(spots)
    return data[:spot] + rng.choice(["é", "名前", "\u2028", "\U0001f916", "·"]).encode() + data[spot:]


def _odd_names(rng: random.Random, data: bytes) -> bytes:
    """Element names the start-tag scanner might not see whole."""
    name = rng.choice([b"\xc3\xa9l", b"a\xc2\xb7b", b"_x", b"a.b-c", b"x1", b"\xe5\x90\x8d"])
    return data.replace(b"<gazebo", b"<" + name, 1).replace(b"</gazebo>", b"</" + name + b">", 1) \
        if b"<gazebo" in data else _chunk(rng, data).replace(b"<plain/>", b"<" + name + b"/>")


def _truncate(rng: random.Random, data: bytes) -> bytes:
    return data[:rng.randrange(len(data))]


def _stray(rng: random.Random, data: bytes) -> bytes:
    spot = rng.randrange(len(data))
    return data[:spot] + rng.choice([b"<", b"&", b">", b'"', b"</x>", b"\x00", b"\xff"]) + data[spot:]


TREE: tuple[Mutation, ...] = tuple(map(_tree, (
    _delete, _duplicate, _move, _rename, _drop_attr, _spoil_attr, _spoil_attr, _spoil_attr, _mesh_path,
    _text, _insert)))
TEXT: tuple[Mutation, ...] = (_one_line, _one_line, _many_lines, _many_lines, _quotes, _spaces, _crlf,
                              _chunk, _chunk, _prolog, _namespaces, _namespaces, _non_ascii,
                              _odd_names, _truncate, _stray)


def mutate(data: bytes, seed: int) -> bytes:
    """One to four mutations of `data`, chosen by `seed`: mostly tree mutations, then a change of
    layout (text mutations last: a tree mutation serialises the text anew)."""
    rng = random.Random(seed)
    for _ in range(rng.randrange(0, 3)):
        data = rng.choice(TREE)(rng, data)
    for _ in range(rng.randrange(0, 3)):
        data = rng.choice(TEXT)(rng, data)
    return data
