"""`@record` behaves as `@dataclass(frozen=True)` would: repr, ==, hash, immutability."""

from __future__ import annotations

import dataclasses
import inspect
from pathlib import Path

import pytest

from mpc.core import record as record_module
from mpc.core.record import bulk_records, maker, record, record_values
from mpc.core.span import Span
from mpc.ir.fragments import Fragment, LazyFragment
from mpc.ir.geometry import Box


@record(slots=True, kw_only=True, bulk=True)
class Pair:
    a: int
    b: tuple[str, ...] = ()


@dataclasses.dataclass(frozen=True, slots=True, kw_only=True)
class DataPair:
    a: int
    b: tuple[str, ...] = ()


@record
class One:
    x: float


def test_repr_eq_and_hash_are_dataclass_ones() -> None:
    mine, theirs = Pair(a=1, b=("x", "y")), DataPair(a=1, b=("x", "y"))
    assert repr(mine) == repr(theirs).replace("DataPair(", "Pair(")
    assert hash(mine) == hash(theirs) == hash((1, ("x", "y")))
    assert mine == Pair(a=1, b=("x", "y")) and mine != Pair(a=2, b=("x", "y"))
    assert mine != theirs  # only the same class is equal
    assert hash(One(2.5)) == hash((2.5,)) and One(2.5) == One(2.5) and repr(One(2.5)) == "One(x=2.5)"


def test_records_are_frozen_dataclasses() -> None:
    pair = Pair(a=1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        pair.a = 2  # type: ignore[misc]
    assert [f.name for f in dataclasses.fields(pair)] == ["a", "b"]
    assert dataclasses.replace(pair, b=("z",)) == Pair(a=1, b=("z",))
    assert not hasattr(pair, "__dict__")  # slots


def test_ir_values_print_as_before() -> None:
    """Mesh digests hash the repr of IR values: it must not change."""
    assert repr(Span("a.yml", 3, 4, 3, 9)) == \
        "Span(file='a.yml', line=3, col=4, end_line=3, end_col=9)"
    box = Box(size=(1.0, 2.0, 3.0))
    assert repr(box) == "Box(size=(1.0, 2.0, 3.0), extra_attrs=())"


@record(slots=True, bulk=True)
class Mixed:
    a: int
    b: str = "b"
    c: list[int] = dataclasses.field(default_factory=list)
    d: tuple[int, ...] = dataclasses.field(default=(), kw_only=True)

    def __post_init__(self) -> None:
        if self.a < 0:
            raise ValueError("a must not be negative")


@record(slots=True, bulk=True)
class Child(Mixed):
    e: float = 0.5


@record(slots=True, bulk=True)
class WithInitVar:
    a: int
    scale: dataclasses.InitVar[int] = 1

    def __post_init__(self, scale: int) -> None:
        object.__setattr__(self, "a", self.a * scale)


def test_slots_records_are_made_as_dataclass_would() -> None:
    """Record's __init__ (the slots' own setters) gives what dataclass's would give: defaults, a
    fresh default_factory value each time, keyword-only fields, __post_init__, inherited fields;
    and the same errors. A record with an InitVar keeps dataclass's."""
    for _ in range(2):  # the first record made puts the fast __init__ in place
        assert repr(Mixed(1)) == "Mixed(a=1, b='b', c=[], d=())"
        assert Mixed(1, "x", [2], d=(3,)) == Mixed(a=1, b="x", c=[2], d=(3,))
        assert Mixed(1).c is not Mixed(1).c
        assert Child(1, "y", e=2.0) == Child(a=1, b="y", c=[], d=(), e=2.0)
        assert WithInitVar(2, 3).a == 6
        with pytest.raises(ValueError, match="negative"):
            Mixed(-1)
        with pytest.raises(TypeError, match=r"Mixed.__init__\(\) missing 1 required positional"):
            Mixed()  # type: ignore[call-arg]
        with pytest.raises(TypeError, match="takes from 2 to 4 positional arguments"):
            Mixed(1, "b", [], ())  # type: ignore[misc]
        with pytest.raises(dataclasses.FrozenInstanceError):
            Mixed(1).a = 2  # type: ignore[misc]
    assert Mixed.__init__.__code__.co_filename == Child.__init__.__code__.co_filename == "<record>"
    assert WithInitVar.__init__.__code__.co_filename == "<string>"  # dataclass's
    assert str(inspect.signature(Mixed)) == \
        "(a: 'int', b: 'str' = 'b', c: 'list[int]' = <factory>, *, d: 'tuple[int, ...]' = ()) -> None"


def test_makers_make_what_the_class_makes() -> None:
    """record.maker: the same record as the class call (defaults, a fresh default_factory
    value, keyword-only fields, __post_init__ and its errors), frozen as any; the class itself
    where it does not apply (a base class, InitVar, no slots)."""
    make = maker(Mixed)
    assert make is maker(Mixed) and make is not Mixed
    assert make(1) == Mixed(1) and type(make(1)) is Mixed
    assert make(1, "x", [2], d=(3,)) == Mixed(1, "x", [2], d=(3,))
    assert make(1).c == [] and make(1).c is not make(1).c
    assert maker(Pair)(a=1) == Pair(a=1) and maker(Pair)(a=2, b=("z",)) == Pair(a=2, b=("z",))
    with pytest.raises(ValueError, match="negative"):
        make(-1)
    with pytest.raises(TypeError):
        maker(Pair)(1)  # type: ignore[misc]  (keyword-only, as Pair(1) is)
    with pytest.raises(dataclasses.FrozenInstanceError):
        make(1).a = 2  # type: ignore[misc]
    assert hash(maker(Pair)(a=1)) == hash(Pair(a=1))
    assert maker(Child) is Child and maker(WithInitVar) is WithInitVar
    assert maker(Span)("f", 3, 4, 1, 1) == Span("f", 3, 4, 1, 1) == Span("f", 3, 4, 3, 4)  # __post_init__


@record(slots=True)
class Plain:
    a: int
    b: str = "b"


@record
class Loose:  # no slots: its fields are set as dataclass's frozen __init__ sets them
    a: int
    b: list[int] = dataclasses.field(default_factory=list)


def test_only_records_made_in_bulk_have_a_maker() -> None:
    assert Plain(1) == Plain(a=1, b="b") and Plain(1) != Plain(2)
    assert Loose(1) == Loose(1, []) and Loose(1).b is not Loose(1).b
    assert Loose(2).__dict__ == {"a": 2, "b": []}
    for cls in (Plain, One, Loose):
        with pytest.raises(TypeError, match="is not made in bulk"):
            maker(cls)
    with pytest.raises(TypeError, match="needs slots"):
        record(bulk=True)


def test_records_are_frozen_as_dataclass_s_are() -> None:
    loose = Loose(1)
    for set_it in (lambda: setattr(loose, "a", 2), lambda: setattr(loose, "other", 2),
                   lambda: delattr(loose, "a")):
        with pytest.raises(dataclasses.FrozenInstanceError):
            set_it()
    assert loose == Loose(1) and dataclasses.replace(loose, a=3) == Loose(3)
    with pytest.raises(TypeError, match="non-default argument 'b' follows default argument"):
        @record
        class Wrong:
            a: int = 1
            b: int  # type: ignore[misc]


# The opt-in list: what the URDF reader makes by the thousand (backends/urdf_reader.py
# _makers), the sources of the meshes it names (ir/geometry.py mesh_source) and the spans of
# every file read (backends/xml.py).
BULK = {"Pose", "FragmentRef", "Robot", "Link", "Inertial", "Inertia", "Box", "Cylinder",
        "Sphere", "Mesh", "MeshSource", "Visual", "Collision", "Material", "Joint", "Limit", "Dynamics",
        "Mimic", "Calibration", "SafetyController", "Span"}


def test_every_class_made_in_bulk_gets_a_maker_with_dataclass_s_parameters() -> None:
    """Each class of the opt-in list gets a maker, not the fallback to the class; its
    parameters, and those of record's __init__, are those of dataclass's __init__ for the same
    fields (run this file on each supported version: it needs only lxml and pytest,
    `--noconftest`)."""
    from mpc.backends import urdf_reader

    urdf_reader._makers()  # the reader's makers: every class it asks for must be on the list
    ours = {cls for cls in bulk_records() if cls.__module__.startswith("mpc.")}
    assert {cls.__qualname__ for cls in ours} == BULK
    for cls in sorted(ours, key=lambda c: c.__qualname__):
        make = maker(cls)
        assert make is not cls and make.__qualname__ == f"{cls.__qualname__}.make", cls
        theirs = _parameters(_dataclass_twin(cls).__init__)[1:]
        assert _parameters(make) == _parameters(record_module._init(cls))[1:] == theirs, cls


def _parameters(function: object) -> list[tuple[str, object, object]]:
    return [(p.name, p.kind, repr(p.default)) for p in inspect.signature(function).parameters.values()]  # type: ignore[arg-type]


def _dataclass_twin(cls: type) -> type:
    """A frozen dataclass of the record's fields (and its __post_init__): what dataclass makes."""
    space: dict[str, object] = {"__annotations__": {f.name: f.type for f in dataclasses.fields(cls)}}
    for f in dataclasses.fields(cls):
        space[f.name] = dataclasses.field(default=f.default, default_factory=f.default_factory,
                                          kw_only=f.kw_only)
    if hasattr(cls, "__post_init__"):
        space["__post_init__"] = cls.__post_init__
    return dataclasses.dataclass(frozen=True)(type(cls.__name__, (), space))


FULL = """<robot name="r" xmlns:x="urn:x">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="base.stl" scale="1 1 1"/></geometry><material name="grey"/></visual>
    <collision><geometry><box size="1 2 3"/></geometry></collision>
    <x:note>kept</x:note>
  </link>
  <link name="arm">
    <visual><geometry><cylinder radius="0.1" length="1"/></geometry></visual>
    <collision><geometry><sphere radius="0.2"/></geometry></collision>
  </link>
  <link name="twin"/>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="3" velocity="4"/><dynamics damping="0.1" friction="0.2"/>
    <calibration rising="0.5"/><safety_controller k_velocity="10" soft_lower_limit="-0.9"/>
  </joint>
  <joint name="k" type="revolute">
    <parent link="arm"/><child link="twin"/><limit lower="-1" upper="1" effort="3" velocity="4"/>
    <mimic joint="j" multiplier="2"/>
  </joint>
  <gazebo reference="base"><plugin name="p"/></gazebo>
</robot>
"""


def test_what_the_reader_makes_is_what_dataclass_s_init_makes(tmp_path: Path) -> None:
    """Every record of a URDF read (made by the makers) equals the same record made by the
    class call (record's __init__), and holds what dataclass's own __init__ makes of the same
    values, for every class listed."""
    from mpc.backends import urdf_reader
    from mpc.backends.xml import XmlSource
    from mpc.core.diagnostics import Sink

    path = tmp_path / "r.urdf"
    path.write_text(FULL, encoding="utf-8")
    robot = urdf_reader.read(path, Sink())
    assert robot is not None
    seen: set[str] = set()
    # The reader's spans are found when asked for (LazySpan), by the parsed file's maker.
    parsed = XmlSource.parse(FULL.encode(), str(path))
    stack: list[object] = [robot, parsed.span(parsed.root)]
    while stack:
        item = stack.pop()
        if isinstance(item, dict):
            stack += item.values()
        elif isinstance(item, tuple | list):
            stack += item
        elif type(item) is LazyFragment:  # its references found when asked for: a Fragment all the same
            values = {f.name: getattr(item, f.name) for f in dataclasses.fields(item)}
            assert item == Fragment(**values) and type(Fragment(**values)) is Fragment
            seen.add("LazyFragment")
            stack += values.values()
        elif type(item) in bulk_records():
            cls = type(item)
            values = {f.name: getattr(item, f.name) for f in dataclasses.fields(item)}
            by_dataclass = _dataclass_twin(cls)(**values)
            theirs = tuple(getattr(by_dataclass, f.name) for f in dataclasses.fields(by_dataclass))
            assert item == cls(**values) and record_values(item) == theirs
            seen.add(cls.__qualname__)
            stack += values.values()
    assert seen == BULK | {"LazyFragment"}


@record
class OwnInit:
    a: int

    def __init__(self, text: str) -> None:
        object.__setattr__(self, "a", int(text))


@record
class FromOwnInit(OwnInit):
    b: int = 0


@record(slots=True)
class FromInitVar(WithInitVar):
    b: int = 0


@dataclasses.dataclass(frozen=True)
class PlainFromRecord(One):
    y: float = 0.0


def test_subclasses_of_records_with_their_own_or_dataclass_s_init() -> None:
    assert OwnInit("3").a == 3 and FromOwnInit(1, 2) == FromOwnInit(a=1, b=2)
    assert PlainFromRecord(1.0, 2.0).y == 2.0 and dataclasses.fields(PlainFromRecord)[0].name == "x"
    with pytest.raises(dataclasses.FrozenInstanceError):
        PlainFromRecord(1.0).x = 2.0  # type: ignore[misc]
    with pytest.raises(TypeError, match="cannot inherit non-frozen dataclass from a frozen one"):
        @dataclasses.dataclass
        class Unfrozen(One):
            y: float = 0.0
    assert FromInitVar(2, 3).a == 6 and FromInitVar(2, 3, 4).b == 4
    with pytest.raises(dataclasses.FrozenInstanceError):
        FromInitVar(1).b = 2  # type: ignore[misc]


@record(frozen=False)
class State:
    name: str
    items: list[int] = dataclasses.field(default_factory=list)
    count: int = dataclasses.field(default=0, kw_only=True)

    def __post_init__(self) -> None:
        self.count += len(self.items)


@dataclasses.dataclass
class DataState:
    name: str
    items: list[int] = dataclasses.field(default_factory=list)
    count: int = dataclasses.field(default=0, kw_only=True)

    def __post_init__(self) -> None:
        self.count += len(self.items)


@record(slots=True, frozen=False)
class SlotState:
    x: float
    y: float = 0.0


def test_mutable_records_are_made_and_behave_as_dataclass_s() -> None:
    """@record(frozen=False) is @dataclass's mutable class: the same __init__ (defaults, a fresh
    default_factory value, keyword-only fields, __post_init__), repr and ==, unhashable, and its
    fields assignable; dataclass compiles none of its methods when the class is made."""
    for _ in range(2):  # the first object made puts the compiled __init__ in place
        mine, theirs = State("a", [1, 2], count=1), DataState("a", [1, 2], count=1)
        assert repr(mine) == repr(theirs).replace("DataState(", "State(") == \
            "State(name='a', items=[1, 2], count=3)"
        assert mine == State("a", [1, 2], count=1) and mine != State("b") and mine != theirs
        assert State("a").items is not State("a").items
        mine.name = "b"
        mine.items.append(3)
        assert mine == State("b", [1, 2, 3], count=0)
        with pytest.raises(TypeError, match="unhashable type: 'State'"):
            hash(mine)
        with pytest.raises(TypeError, match=r"State.__init__\(\) missing 1 required positional"):
            State()  # type: ignore[call-arg]
    assert State.__init__.__code__.co_filename == "<record>"
    assert str(inspect.signature(State)) == str(inspect.signature(DataState))
    assert [f.name for f in dataclasses.fields(State)] == ["name", "items", "count"]
    assert repr(dataclasses.replace(State("a", [1]), name="c")) == \
        repr(dataclasses.replace(DataState("a", [1]), name="c")).replace("DataState(", "State(")
    assert not record_module.is_record(State)  # the build cache reads none back
    state = SlotState(1.0)
    state.y = 2.0
    assert state == SlotState(1.0, 2.0) and not hasattr(state, "__dict__")
    with pytest.raises(TypeError, match="@record\\(bulk=True\\) is frozen"):
        record(slots=True, bulk=True, frozen=False)


def test_mpc_makes_its_classes_of_fields_with_record() -> None:
    """A `@dataclass` compiles its methods when its module is imported (three to six exec calls,
    0.2–0.9 ms a class): mpc's classes are records. The one exception is hashed by identity."""
    import re

    from mpc.core.version import source_files

    found = [f"{name}: {m.group(0).strip()}" for name, file in source_files() if name.endswith(".py")
             for m in re.finditer(r"^[ \t]*@(?:dataclasses\.)?dataclass\b.*$",
                                  file.read_text(encoding="utf-8"), re.M)]
    assert found == ["ir/text_types.py: @dataclass(frozen=True, eq=False)  # hashed by identity: "
                     "printing caches per registry"]
