"""The URDF reader and XmlSource against frozen copies of themselves as they were before they
became faster (issue 19): the same IR (spans included) and the same diagnostics for every URDF
of example-robot-data, the suite's own URDF files, hostile inputs and seeded mutations of them
all; the same span for every element and attribute of those files and of SDF files.

The frozen copies (urdf_reader_before.py, xml_source_before.py) exist only for this test: a
faster reader must read exactly what the old one read, and nothing else shows a difference in
a column or in a fragment's bytes as surely.
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from lxml import etree

from mpc.backends import sdf, urdf_reader
from mpc.backends.xml import XmlError, XmlSource, parse_floats
from mpc.core.diagnostics import Diagnostic, Sink
from mpc.core.packages import PackageResolver
from tests.backends import refusal_before, urdf_reader_before, xml_source_before
from tests.backends.urdf_mutations import mutate
from tests.conftest import ERD

HERE = Path(__file__).resolve().parent
URDFS = sorted(ERD.rglob("*.urdf")) + sorted((HERE.parent / "compiler").rglob("*.urdf"))
SDFS = sorted(HERE.parent.rglob("*.sdf"))
# HYPOTHESIS_PROFILE=long (tests/conftest.py) digs deeper here too.
MUTATIONS = 4000 if os.environ.get("HYPOTHESIS_PROFILE") == "long" else 480
CHUNKS = 8

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


def _diagnostics(sink: Sink) -> list[Diagnostic]:
    return list(sink.diagnostics)


_OUTSIDE = "outside the project and the model's package roots"


def compare_urdf(data: bytes, file: str, base_dir: Path) -> str | None:
    """What differs between the two readers' IR and diagnostics for `data`, or None."""
    old_sink, new_sink = Sink(), Sink()
    old = urdf_reader_before.read_text(data, file, base_dir, old_sink, PackageResolver())
    new = urdf_reader.read_text(data, file, base_dir, new_sink, PackageResolver())
    if any(d.code == "E0650" and d.message.endswith(_OUTSIDE) for d in new_sink.diagnostics) and \
            not any(d.code == "E0650" and d.message.endswith(_OUTSIDE) for d in old_sink.diagnostics):
        return None  # issue 35: a mesh at a plain path out of the roots is refused; the frozen reader read it
    # == is the test; nan is never == nan, so the texts excuse it (they show -0.0 too).
    if repr(old) != repr(new) or (old != new and "nan" not in repr(old)):
        return f"IR differs:\n  before {old!r}\n  after  {new!r}"
    if _diagnostics(old_sink) != _diagnostics(new_sink):
        return f"diagnostics differ:\n  before {old_sink.diagnostics}\n  after  {new_sink.diagnostics}"
    return None


def compare_spans(data: bytes, file: str) -> str | None:
    """What differs between the two XmlSources' spans of every element and attribute (and of
    one attribute no element has), or their errors, for `data`; None when nothing does."""
    try:
        old = xml_source_before.XmlSource.parse(data, file)
    except xml_source_before.XmlError as e:
        try:
            XmlSource.parse(data, file)
        except XmlError as f:
            same = (e.message, e.line, e.col) == (f.message, f.line, f.col)
            return None if same else f"errors differ: {e.message, e.line, e.col} {f.message, f.line, f.col}"
        return f"only the old XmlSource refuses it: {e.message}"
    try:
        new = XmlSource.parse(data, file)
    except XmlError as f:
        return f"only the new XmlSource refuses it: {f.message}"
    if old.text != new.text:
        return "texts differ"
    pairs = zip(old.root.iter(etree.Element), new.root.iter(etree.Element), strict=True)
    for el_old, el_new in pairs:
        for attr in (None, *el_old.keys(), "absent"):
            if old.span(el_old, attr) != new.span(el_new, attr):
                return f"<{el_old.tag}> {attr}: {old.span(el_old, attr)!r} {new.span(el_new, attr)!r}"
    return None


def _documents() -> Iterator[tuple[str, bytes, Path]]:
    """Every file this test starts from: (name, bytes, its folder)."""
    for path in URDFS:
        yield str(path), path.read_bytes(), path.parent.resolve()


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.name)
def test_every_urdf_reads_the_same(path: Path) -> None:
    data = path.read_bytes()
    assert compare_urdf(data, str(path), path.parent.resolve()) is None
    assert compare_spans(data, str(path)) is None
    old_sink, new_sink = Sink(), Sink()  # and through read(): the file's own path
    old, new = urdf_reader_before.read(path, old_sink), urdf_reader.read(path, new_sink)
    assert old == new and repr(old) == repr(new)
    assert old_sink.diagnostics == new_sink.diagnostics


@pytest.mark.parametrize("path", SDFS, ids=lambda p: p.name)
def test_every_sdf_is_located_the_same(path: Path) -> None:
    assert compare_spans(path.read_bytes(), str(path)) is None


@pytest.mark.parametrize("path", URDFS[::4], ids=lambda p: p.name)
def test_sdf_written_from_urdf_is_located_the_same(path: Path) -> None:
    """The SDF reader's XmlSource: mpc's own SDF of the model, and mutations of it."""
    robot = urdf_reader.read(path, Sink())
    if robot is None:
        return
    data = sdf.to_string(robot, lambda mesh: mesh.source.uri).encode()
    for seed in range(8):
        assert compare_spans(mutate(data, seed) if seed else data, str(path)) is None


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_inputs_read_the_same(name: str, tmp_path: Path) -> None:
    (tmp_path / "m.stl").write_bytes(b"solid m\nendsolid m\n")
    (tmp_path / "link.stl").symlink_to("/etc/hostname")
    data = HOSTILE[name]
    for variant in (data, data.replace(b"m.stl", b"link.stl")):
        assert compare_urdf(variant, name, tmp_path) is None
        assert compare_spans(variant, name) is None


_WORDS = ["0", "1", "-2.5", "1e3", ".5", "inf", "nan", "1_0", "x", "0x1", "", "١"]
_NUMBER_TEXT = st.lists(st.sampled_from(_WORDS) | st.floats().map(repr), max_size=4).flatmap(
    lambda words: st.lists(st.sampled_from([" ", "  ", "\t", "\n", "\u00a0", "\u2028", ""]),
                           min_size=len(words) + 1, max_size=len(words) + 1).map(
        lambda spaces: "".join(a + b for a, b in zip(spaces, [*words, ""], strict=True))))


@given(_NUMBER_TEXT | st.text(max_size=12))
def test_numbers_are_read_the_same(text: str) -> None:
    """parse_floats's shortcut for one number (float() alone) against split() and float()."""
    assert parse_floats(text) == xml_source_before.parse_floats(text) or (
        repr(parse_floats(text)) == repr(xml_source_before.parse_floats(text)))  # nan != nan


def _outcome(refuse: Callable[..., str | None], *args: object) -> str | None:
    try:
        return refuse(*args)
    except OSError as e:  # Path.exists raises on some errors (ENAMETOOLONG), then and now
        return f"raised {type(e).__name__}: {e}"


def test_refusals_are_the_same(tmp_path: Path) -> None:
    """PackageResolver.refusal against its frozen copy, for files, folders, links in and out
    of the package, special files and paths written every way."""
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
    for order in range(3):
        shuffled = random.Random(order).sample(paths, len(paths))
        for base in (pkg, None):
            old, new = PackageResolver(), PackageResolver()
            for path in shuffled + shuffled:  # and again, from the resolvers' caches
                before = _outcome(refusal_before.refusal, old, path, base)
                now = _outcome(new.refusal, path, base)
                if before is None and now is not None:
                    # The frozen copy refused only links out of the roots; a plain path out of
                    # them is refused now too (issue 35): the same file, named without a link.
                    real = os.path.realpath(path)
                    assert now == f"it is '{real}', outside the project and the model's package roots"
                    assert base is None or not real.startswith(f"{base}/"), (path, base)
                else:
                    assert now == before, (path, base)


@pytest.mark.parametrize("chunk", range(CHUNKS))
def test_mutated_urdfs_read_the_same(chunk: int) -> None:
    """MUTATIONS seeded mutations in all, small models more often than large ones (a mutation
    of TALOS takes 40 ms to compare)."""
    documents = list(_documents())
    weights = [1 / (1 + len(data) / 20_000) for _, data, _ in documents]
    differences = []
    for seed in range(chunk, MUTATIONS, CHUNKS):
        rng = random.Random(seed)
        name, data, folder = rng.choices(documents, weights)[0]
        mutated = mutate(data, seed)
        for what in (compare_urdf(mutated, name, folder), compare_spans(mutated, name)):
            if what is not None:
                differences.append(f"seed {seed} ({name}): {what}")
    assert differences == []
