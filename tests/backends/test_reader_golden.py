"""The URDF reader and XmlSource against their recorded outputs (tests/golden.py): the IR
(spans included) and the diagnostics for every URDF of example-robot-data, the suite's own
URDF files, hostile inputs and seeded mutations of them all; the span of every element and
attribute of those files and of SDF files; PackageResolver's refusals.

A case is recorded as the digest of its text (`case_text`); a few readable ones are kept
whole. The records were made by the reader of issue 19 (the one that read the same as its
frozen predecessor), and `MPC_UPDATE_GOLDEN=1` makes them again: a change of the reader shows
as the cases it changes in the fixture's diff. Whether what is read is *right* is for the
tests of the reader (test_urdf_reader.py) and of the round trip against Pinocchio
(test_roundtrip.py).
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from lxml import etree

from mpc.backends import sdf, urdf_reader
from mpc.backends.xml import NOT_FINITE, XmlError, XmlSource, finite_floats, parse_floats
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.ir.robot import Robot
from tests.backends.urdf_mutations import mutate
from tests.conftest import ERD
from tests.golden import check_digests, check_text, diagnostic_lines, digest, stable, value_lines

HERE = Path(__file__).resolve().parent
URDFS = sorted(ERD.rglob("*.urdf")) + sorted((HERE.parent / "compiler").rglob("*.urdf"))
SDFS = sorted(HERE.parent.rglob("*.sdf"))
# HYPOTHESIS_PROFILE=long (tests/conftest.py) digs deeper in the property test; the recorded
# mutations are a fixed set.
MUTATIONS = 480
# Readable cases kept whole besides their digests.
WHOLE = {"double_pendulum_simple.urdf", "hostile crlf.urdf", "hostile escape.urdf",
         "hostile one_line.urdf", "seed 6", "seed 7"}

HOSTILE = {
    "entity.urdf": b'<!DOCTYPE robot [<!ENTITY e "x">]><robot name="r"><link name="&e;"/></robot>',
    "external.urdf": b'<!DOCTYPE robot SYSTEM "file:///etc/passwd"><robot name="r"><link name="a"/></robot>',
    "billion.urdf": b'<!DOCTYPE r [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]><robot name="&b;"/>',
    "subset.urdf": b'<!DOCTYPE robot [<!ELEMENT robot ANY><!ENTITY e "<link name=\'e\'/>">]>\n'
                   b'<robot name="r">\n <link name="a"/>\n <link name="a"/>\n</robot>',
    "utf7.urdf": b'<?xml version="1.0" encoding="UTF-7"?>\n<robot name="r">\n +ADw-link name="a"/+AD4-\n'
                 b' <link name="a"/>\n</robot>',
    "not_xml.urdf": b"this is not XML",
    "empty.urdf": b"",
    "bom.urdf": b'\xef\xbb\xbf<robot name="r">\n  <link name="a"/>\n</robot>\n',
    "latin1.urdf": b'<?xml version="1.0" encoding="ISO-8859-1"?>\n<robot name="r\xe9">\n'
                   b' <link name="\xe9"/>\n</robot>',
    "crlf.urdf": b'<robot name="r">\r\n  <link name="a"/>\r\n  <joint name="j" type="revolute">\r\n'
                 b'    <parent link="a"/><child link="b"/>\r\n  </joint>\r\n'
                 b'  <link\r\n name="b"/>\r\n</robot>',
    "cr.urdf": b'<robot name="r">\r  <link name="a"/>\r  <link name="a"/>\r</robot>',
    "namespaces.urdf": b'<robot name="r" xmlns="urn:d" xmlns:x="urn:x">\n <link name="a" x:b="1"/>\n'
                       b' <x:gazebo reference="a"><x:mu>1</x:mu></x:gazebo>\n</robot>',
    "unused_ns.urdf": b'<robot name="r" xmlns:u="urn:u" xmlns:x="urn:x">\n <link name="a" xmlns:v="urn:v">\n'
                      b'  <gazebo><mu1>1</mu1></gazebo>\n  <x:y xmlns:w="urn:w"/>\n </link>\n'
                      b' <gazebo reference="a" xmlns:w="urn:w"><x:z/></gazebo>\n</robot>',
    "undeclared.urdf": b'<robot name="r">\n <link name="a"><visual><geometry><u:mesh filename="m.stl"/>'
                       b'</geometry></visual></link>\n <u:gazebo reference="a"/>\n</robot>',
    "one_line.urdf": b'<robot name="r"><link name="a"><visual><geometry><box size="1 1"/></geometry>'
                     b'</visual></link><link name="a"/><joint name="j" type="screw"><parent link="a"/>'
                     b'</joint><gazebo reference="a"><x>a</x></gazebo></robot>',
    "cdata.urdf": b'<robot name="r">\n <link name="a"/>\n <gazebo reference="a"><![CDATA[a]]><plugin>'
                  b'<![CDATA[ <x> & ]]></plugin></gazebo>\n <?pi x?>\n</robot>',
    "proc.urdf": b'<robot name="r">\n <link name="a"><visual><geometry><mesh filename="/proc/self/environ"/>'
                 b'</geometry></visual><collision><geometry><mesh filename="file:///dev/zero"/></geometry>'
                 b'</collision></link>\n</robot>',
    "escape.urdf": b'<robot name="r">\n <link name="a"><visual><geometry>'
                   b'<mesh filename="../../../../../../../etc/passwd"/>'
                   b'</geometry></visual></link>\n</robot>',
    "odd_names.urdf": b'<robot name="r">\n <link name="a"/>\n <\xc3\xa9l a="1"/>\n <a\xc2\xb7b/>\n</robot>',
    "colon_start.urdf": b'<robot name="r">\n <link name="a"/>\n <:x/>\n</robot>',
    "gt_in_attr.urdf": b'<robot name="r">\n <link name="a>b"><visual><geometry>'
                       b'<mesh x="a>b" filename="m.stl"/>'
                       b'</geometry></visual></link>\n</robot>',
}


def case_text(data: bytes, file: str, base_dir: Path, tmp: Path | None = None) -> str:
    """What the reader makes of `data` (its IR, or None, and its diagnostics) and where
    XmlSource puts each element and attribute, as text that does not depend on the machine."""
    sink = Sink()
    robot = urdf_reader.read_text(data, file, base_dir, sink, PackageResolver())
    return stable("\n".join([*read_lines(robot, sink), "# spans", *span_lines(data, file)]) + "\n", tmp)


def read_lines(robot: Robot | None, sink: Sink) -> list[str]:
    return ["# IR", *value_lines(robot), "# diagnostics", *diagnostic_lines(sink.diagnostics)]


def span_lines(data: bytes, file: str) -> list[str]:
    """The span of every element's start tag and of each of its attributes (and of one
    attribute no element has), or the error that refuses the text."""
    try:
        source = XmlSource.parse(data, file)
    except XmlError as e:
        return [f"refused {e.line}:{e.col}: {e.message}"]
    lines = [f"text {digest(source.text)}"]
    for el in source.root.iter(etree.Element):
        for attr in (None, *el.keys(), "absent"):
            s = source.span(el, attr)
            lines.append(f"<{el.tag}> {attr}: {s.line}:{s.col}-{s.end_line}:{s.end_col}")
    return lines


def _name(path: Path) -> str:
    return str(path.relative_to(ERD)) if path.is_relative_to(ERD) else str(path.relative_to(HERE.parent))


def _check(name: str, texts: dict[str, str]) -> None:
    """The digest of every case against record NAME, then the cases of WHOLE against their
    whole texts (which show what changed)."""
    check_digests(name, {case: digest(text) for case, text in texts.items()})
    for case, text in texts.items():
        if case in WHOLE or Path(case).name in WHOLE:
            check_text(f"reader/{case.replace('/', '_').replace(' ', '_')}", text)


def test_every_urdf_reads_as_recorded() -> None:
    found: dict[str, str] = {}
    for path in URDFS:
        data = path.read_bytes()
        text = found[_name(path)] = case_text(data, str(path), path.parent.resolve())
        sink = Sink()  # and through read(): the file's own path, the same IR and diagnostics
        robot = urdf_reader.read(path, sink)
        assert text.startswith(stable("\n".join([*read_lines(robot, sink), "# spans\n"])))
    assert len(found) > 50
    _check("reader_urdfs", found)


def test_every_sdf_is_located_as_recorded() -> None:
    found = {_name(p): digest(stable("\n".join(span_lines(p.read_bytes(), str(p))))) for p in SDFS}
    check_digests("reader_sdf_spans", found)


def test_sdf_written_from_urdf_is_located_as_recorded() -> None:
    """The SDF reader's XmlSource: mpc's own SDF of the model, and mutations of it."""
    found = {}
    for path in URDFS[::4]:
        robot = urdf_reader.read(path, Sink())
        if robot is None:
            continue
        data = sdf.to_string(robot, lambda mesh: mesh.source.uri).encode()
        for seed in range(8):
            spans = span_lines(mutate(data, seed) if seed else data, str(path))
            found[f"{_name(path)} seed {seed}"] = digest(stable("\n".join(spans)))
    check_digests("reader_sdf_of_urdf_spans", found)


def test_hostile_inputs_read_as_recorded(tmp_path: Path) -> None:
    (tmp_path / "m.stl").write_bytes(b"solid m\nendsolid m\n")
    (tmp_path / "link.stl").symlink_to("/etc/hostname")
    found = {}
    for name, data in HOSTILE.items():
        for case, variant in ((name, data), (f"{name} link", data.replace(b"m.stl", b"link.stl"))):
            found[f"hostile {case}"] = case_text(variant, name, tmp_path, tmp_path)
    _check("reader_hostile", found)


def test_mutated_urdfs_read_as_recorded() -> None:
    """MUTATIONS seeded mutations in all, small models more often than large ones."""
    documents = [(path, path.read_bytes()) for path in URDFS]
    weights = [1 / (1 + len(data) / 20_000) for _, data in documents]
    found = {}
    for seed in range(MUTATIONS):
        rng = random.Random(seed)
        path, data = rng.choices(documents, weights)[0]
        text = case_text(mutate(data, seed), str(path), path.parent.resolve())
        found[f"seed {seed}"] = f"# {_name(path)}\n{text}"
    _check("reader_mutations", found)


_WORDS = ["0", "1", "-2.5", "1e3", ".5", "inf", "nan", "1_0", "x", "0x1", "", "١"]
_NUMBER_TEXT = st.lists(st.sampled_from(_WORDS) | st.floats().map(repr), max_size=4).flatmap(
    lambda words: st.lists(st.sampled_from([" ", "  ", "\t", "\n", "\u00a0", "\u2028", ""]),
                           min_size=len(words) + 1, max_size=len(words) + 1).map(
        lambda spaces: "".join(a + b for a, b in zip(spaces, [*words, ""], strict=True))))


def _numbers(text: str) -> tuple[float, ...] | None:
    """What URDF means by a list of numbers: the whitespace-separated words, each a float as
    Python reads it, but with no `_` (1_0 is no URDF number); None when any word is not one."""
    if "_" in text:
        return None
    try:
        return tuple(float(word) for word in text.split())
    except ValueError:
        return None


@given(_NUMBER_TEXT | st.text(max_size=12))
def test_numbers_are_read_as_urdf_means(text: str) -> None:
    """parse_floats's shortcut for one number (float() alone) against split() and float()."""
    assert repr(parse_floats(text)) == repr(_numbers(text))  # repr: nan != nan


@given(_NUMBER_TEXT | st.text(max_size=12) | st.floats().map(repr))
@example('1_0')
@example('-inf')
@example('1e400')
@example('nan')
@example(' 1')
@example('1\x1c')
@example('0x1')
@example('')
@example('1 2')
def test_one_number_is_read_as_finite_floats_reads_it(text: str) -> None:
    """The reader's shortcut for the text of one number (urdf_reader._one_number) against
    finite_floats, whatever the text: the same numbers, refusals and NOT_FINITE."""
    ours, theirs = urdf_reader._one_number(text), finite_floats(text)
    assert (ours is NOT_FINITE) == (theirs is NOT_FINITE) and repr(ours) == repr(theirs)


def test_numbers_examples() -> None:
    assert parse_floats(" 1\t-2.5\n1e3 ") == (1.0, -2.5, 1000.0)
    assert parse_floats("1_0") is None and parse_floats("1 x") is None and parse_floats(None) is None
    assert parse_floats("") == () and parse_floats("\u00a01\u00a0") == (1.0,)


def _outcome(refuse: Callable[..., str | None], *args: object) -> str | None:
    try:
        return refuse(*args)
    except OSError as e:  # Path.exists raises on some errors (ENAMETOOLONG)
        return f"raised {type(e).__name__}: {e}"


def test_refusals_are_as_recorded(tmp_path: Path) -> None:
    """PackageResolver.refusal for files, folders, links in and out of the package, special
    files and paths written every way, fresh and from the resolver's cache."""
    pkg, outside = tmp_path / "pkg", tmp_path / "outside"
    meshes = pkg / "meshes"
    (meshes / "dir").mkdir(parents=True)
    outside.mkdir()
    for file in (meshes / "a.stl", meshes / ".hidden.stl", outside / "x.stl"):
        file.write_bytes(b"solid\nendsolid\n")
    links = {"in.stl": "a.stl", "out.stl": str(outside / "x.stl"), "proc": "/proc/self/environ",
             "dangling": "/nonexistent/x", "loop": "loop", "devnull": "/dev/null", "up": "../meshes/a.stl"}
    for name, target in links.items():
        (meshes / name).symlink_to(target)
    (pkg / "linked_out").symlink_to(outside)
    (pkg / "linked_in").symlink_to(meshes)
    os.mkfifo(meshes / "fifo")
    names = ["a.stl", ".hidden.stl", "dir", "missing.stl", "fifo", *links, "a.stl/x", "x" * 300]
    paths = [meshes / n for n in names] + [
        pkg / "linked_out/x.stl", pkg / "linked_in/a.stl", pkg / "linked_in/out.stl",
        pkg / "linked_out/missing", meshes / "../meshes/a.stl", meshes / "dir/../a.stl",
        Path(f"{meshes}/./a.stl"), Path(f"{meshes}//a.stl"), Path(f"{meshes}/"), Path("meshes/a.stl"),
        Path("/dev/null"), Path("/proc/self/environ"), Path("/proc"), Path("/"), Path("/etc/hostname"),
        Path("/nonexistent/x"), outside / "x.stl", Path(str(tmp_path) + "/pkg/../outside/x.stl"),
        pkg / "linked_out/../pkg/meshes/a.stl", Path("//etc/hostname"), Path(f"/{meshes}/a.stl")]
    found = {}
    for order in range(3):
        shuffled = random.Random(order).sample(paths, len(paths))
        for base in (pkg, None):
            resolver = PackageResolver()
            outcomes = [(path, _outcome(resolver.refusal, path, base)) for path in shuffled]
            again = [(path, _outcome(resolver.refusal, path, base)) for path in shuffled]
            assert again == outcomes  # the resolver's cache answers as it did
            for path, outcome in outcomes:
                found[stable(f"{path} in {base}", tmp_path)] = stable(str(outcome), tmp_path)
    check_text("reader/refusals", "".join(f"{k}: {v}\n" for k, v in sorted(found.items())))


def test_a_fragment_names_each_link_and_joint_by_its_kind(tmp_path: Path) -> None:
    """A fragment's refs (backends/urdf_fragments.py), in document order: a name only a link or
    only a joint has is of that kind; one that both have is a joint's where the attribute or
    tag says joint, else a link's; nested places by their child indices."""
    data = b"""<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="b" type="fixed"><parent link="a"/><child link="b"/></joint>
  <gazebo reference="b"><joint_of>b</joint_of><x link=" a " joint="b"/><!-- a --><t> b </t></gazebo>
  <transmission name="t"><joint name="b"/><actuator> b</actuator></transmission>
</robot>
"""
    robot = urdf_reader.read_text(data, "r.urdf", tmp_path, Sink(), PackageResolver())
    assert robot is not None
    assert [[(r.path, r.attr, r.kind, r.name) for r in f.refs] for f in robot.fragments] == [
        [((), "reference", "link", "b"), ((0,), None, "joint", "b"), ((1,), "link", "link", "a"),
         ((1,), "joint", "joint", "b"), ((3,), None, "link", "b")],
        [((0,), "name", "joint", "b"), ((1,), None, "link", "b")]]


@pytest.mark.parametrize(("before", "xml"), [
    ("\n  ", '<gazebo reference="a">\n  <x/>\n</gazebo>'),  # less its start tag's indentation
    ("\n\t  ", '<gazebo reference="a">\n <x/>\n  </gazebo>'),  # 3 characters, as its column says
    # Text before the tag that is no indentation as written: its column (6, 13 and 23) decides.
    ("\n  <!--c--><![CDATA[\n  ]]>", '<gazebo reference="a">\n    <x/>\n  </gazebo>'),
    ("\n  &#32;&#32;", '<gazebo reference="a">\n    <x/>\n  </gazebo>'),
    ("\n  <material name='m'/>", '<gazebo reference="a">\n    <x/>\n  </gazebo>'),
], ids=["spaces", "a tab", "a CDATA section", "character references", "an element"])
def test_a_fragment_keeps_its_lines_less_the_indentation_of_its_start_tag(
        tmp_path: Path, before: str, xml: str) -> None:
    data = (f'<robot name="r">\n  <link name="a"/>{before}<gazebo reference="a">\n'
            '    <x/>\n  </gazebo>\n</robot>\n').encode()
    robot = urdf_reader.read_text(data, "r.urdf", tmp_path, Sink(), PackageResolver())
    assert robot is not None
    assert [f.xml for f in robot.fragments] == [xml]
