"""Lazy fragments (ir/fragments.py): the URDF reader's fragments find the link and joint names
they mention when first asked for, and are then Fragments in every way a user relies on: equal,
hashed, printed, pickled, copied, replaced and kept as one, with the references an eager walk
finds."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from pathlib import Path

from mpc.backends import urdf
from mpc.compiler import kept_values
from mpc.core.diagnostics import Sink
from mpc.core.span import Span, settle_spans
from mpc.ir.fragments import Fragment, FragmentRef, LazyFragment
from mpc.ir.rename import rename_fragment
from mpc.ir.robot import Robot

URDF = """<robot name="r">
  <link name="base"/>
  <link name="arm"/>
  <joint name="j" type="fixed">
    <parent link="base"/>
    <child link="arm"/>
  </joint>
  <gazebo reference="arm">
    <sensor name="s"><pose> base </pose></sensor>
  </gazebo>
  <!-- the drive -->
  <transmission name="t">
    <joint name="j"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
  </transmission>
</robot>
"""

GAZEBO_REFS = (FragmentRef((), "reference", "link", "arm"), FragmentRef((0, 0), None, "link", "base"))
TRANSMISSION_REFS = (FragmentRef((0,), "name", "joint", "j"),)  # `t` names no link or joint


def _read(tmp_path: Path, text: str = URDF) -> Robot:
    path = tmp_path / "r.urdf"
    path.write_text(text, encoding="utf-8")
    robot = urdf.read(path, Sink())
    assert robot is not None
    return robot


def _unfound(fragment: Fragment) -> bool:
    """Whether the fragment's references are still to be found (their slot not set)."""
    try:
        Fragment.__dict__["refs"].__get__(fragment)
    except AttributeError:
        return True
    return False


def test_a_read_fragment_finds_its_references_when_asked_then_lets_the_parse_go(tmp_path: Path) -> None:
    gazebo, transmission = _read(tmp_path).fragments
    assert type(gazebo) is LazyFragment and _unfound(gazebo) and _unfound(transmission)
    assert gazebo.xml == ('<gazebo reference="arm">\n  <sensor name="s"><pose> base </pose></sensor>\n'
                          "</gazebo>")  # the text is the reader's, found at once
    assert transmission.comments == (" the drive ",)
    assert gazebo.refs == GAZEBO_REFS and not _unfound(gazebo)
    assert object.__getattribute__(gazebo, "_finder") is None  # the parsed file let go
    assert object.__getattribute__(gazebo, "_node") is None
    assert transmission.names("joint") == frozenset({"j"}) and transmission.refs == TRANSMISSION_REFS


def test_a_lazy_fragment_is_the_fragment_an_eager_read_makes(tmp_path: Path) -> None:
    lazy = _read(tmp_path).fragments[0]
    span = Span(str(tmp_path / "r.urdf"), 8, 3, 8, 10)
    eager = Fragment(tag="gazebo", xml=lazy.xml, refs=GAZEBO_REFS, comments=(), span=span)
    assert lazy == eager and eager == lazy and hash(lazy) == hash(eager)
    assert repr(lazy) == repr(eager) and repr(lazy).startswith("Fragment(tag='gazebo', xml=")
    assert lazy != dataclasses.replace(eager, refs=GAZEBO_REFS[:1])
    assert dataclasses.asdict(lazy) == dataclasses.asdict(eager)
    fresh = _read(tmp_path).fragments[0]  # none of its fields asked for before these
    for kept in (pickle.loads(pickle.dumps(fresh)), copy.deepcopy(_read(tmp_path).fragments[0]),
                 kept_values.loads(kept_values.dumps(_read(tmp_path).fragments[0]))):
        assert type(kept) is Fragment and kept == eager
    assert kept_values.dumps(_read(tmp_path).fragments[0]) == kept_values.dumps(eager)


def test_a_replaced_or_renamed_lazy_fragment_keeps_its_references(tmp_path: Path) -> None:
    gazebo = _read(tmp_path).fragments[0]
    moved = dataclasses.replace(gazebo, comments=("moved",))
    assert moved.refs == GAZEBO_REFS and moved.comments == ("moved",)
    renamed = rename_fragment(_read(tmp_path).fragments[0], lambda n: {"arm": "forearm"}.get(n, n),
                              lambda n: n)
    assert renamed.xml.startswith('<gazebo reference="forearm">')
    assert renamed.refs == (FragmentRef((), "reference", "link", "forearm"), GAZEBO_REFS[1])


def test_settling_a_robot_s_spans_finds_its_fragments_references(tmp_path: Path) -> None:
    """What enters a long-lived cache keeps no parsed file alive (core/span.py: settle_spans):
    each fragment's references are found, and its finder let go, as its span's."""
    robot = _read(tmp_path)
    assert settle_spans(robot) > 0
    for fragment in robot.fragments:
        assert not _unfound(fragment) and object.__getattribute__(fragment, "_finder") is None
    assert robot.fragments[0].refs == GAZEBO_REFS and robot.fragments[1].refs == TRANSMISSION_REFS
