"""Declared references: which fields of the IR's records name a link, joint, collision, visual,
material, motor, sensor or pose, and one walk over them.

A field declares what it names by its type: `link: LinkRef` names a link that must exist,
`name: LinkName` is the name of a link the record defines (an op that adds one, or the link
itself), `targets: tuple[LinkOrJointRef, ...]` a joint, else a link of that name. Each of these
is `Annotated[str, Ref(kinds)]`; a new kind of name is one more such alias here.

The declarations are read from the fields' resolved types (`typing.get_type_hints` with
`include_extras`), not from their text: an alias (`MovedLink = LinkRef`), `Optional[LinkRef]`,
`LinkRef | None`, a tuple, list, set or mapping of references, a NewType over a record, all
declare what they resolve to. A class's types are resolved once, when a record of it is first
walked (`mpc check` resolves only the classes of the ops a definition uses). A union whose
members declare different things cannot be walked (a string is a string) and is refused with
TypeError; tests/ir/test_refs.py resolves every record class of the IR, so that shows in tests.

Free data (annotations, submechanism definitions as written) has no types: FREE_DATA declares
the keys in it that the SMURF is known to hold names under, by a path pattern per record field.

`refs(obj)` lists what a record names (op `reads()`, name checks), `renamed(obj, rename)` gives
the record with every declared reference passed through `rename(kinds, name)` (ir/rename.py),
`pruned(obj, gone)` the record without the references in sequences that name what is gone, and
`names_only(obj, kept)` whether everything a record uses is kept (cutting, merging). What this
does not do: decide what a name means (that is the op's).
"""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from collections import abc
from collections.abc import Callable, Iterator, Mapping
from fnmatch import fnmatchcase
from typing import Annotated, Any, Union, get_args, get_origin

from mpc.core.record import record


@record(slots=True)
class Ref:
    """The mark of a field that names an element: the kinds it may be (the first one that has
    the name, in this order), and whether the record defines the name rather than uses it."""

    kinds: tuple[str, ...]
    defines: bool = False


LinkRef = Annotated[str, Ref(("link",))]
JointRef = Annotated[str, Ref(("joint",))]
CollisionRef = Annotated[str, Ref(("collision",))]
VisualRef = Annotated[str, Ref(("visual",))]
MaterialRef = Annotated[str, Ref(("material",))]
MotorRef = Annotated[str, Ref(("motor",))]
LinkOrJointRef = Annotated[str, Ref(("joint", "link"))]
LinkName = Annotated[str, Ref(("link",), defines=True)]
CollisionName = Annotated[str, Ref(("collision",), defines=True)]
VisualName = Annotated[str, Ref(("visual",), defines=True)]
JointName = Annotated[str, Ref(("joint",), defines=True)]
MaterialName = Annotated[str, Ref(("material",), defines=True)]
MotorName = Annotated[str, Ref(("motor",), defines=True)]
SensorName = Annotated[str, Ref(("sensor",), defines=True)]
PoseName = Annotated[str, Ref(("pose",), defines=True)]
SubmechanismName = Annotated[str, Ref(("submechanism",), defines=True)]

# Names in free data: (record class, field) → (path pattern, declaration) pairs. A pattern's
# parts match keys or item positions as fnmatch does (`*` any, `jointnames*` every key so begun).
FREE_DATA: dict[tuple[str, str], tuple[tuple[str, Ref], ...]] = {
    ("Submechanism", "definition"): (("jointnames*/*", Ref(("joint",))), ("around", Ref(("link",))),
                                     ("loop_constraints/*/*_body", Ref(("link",)))),
    ("Joint", "annotations"): (("movement_depends_on/*/joint_name", Ref(("joint",))),),
    ("Robot", "annotations"): (("self_collision/may_collide/*/*", Ref(("link",))),),
}

# A field's shape, from its resolved type: ("ref", Ref) | ("record",) (a record, or Any: look at
# the value) | ("seq", shape) | ("items", (shape, …)) for a tuple of fixed length | ("map", key
# shape, value shape) | ("free", ((pattern parts, Ref), …)) for free data (FREE_DATA); None:
# nothing declared in it.
Shape = tuple[Any, ...] | None
Rename = Callable[[tuple[str, ...], str], str]  # (the kinds it may be, name) → new name

_SEQUENCES = (tuple, list, frozenset, set, abc.Sequence, abc.MutableSequence, abc.Set, abc.MutableSet,
              abc.Collection, abc.Iterable)
_MAPPINGS = (dict, abc.Mapping, abc.MutableMapping, types.MappingProxyType)
_SHAPES: dict[type, tuple[tuple[str, Shape], ...]] = {}


@functools.cache
def type_hints(cls: type) -> dict[str, Any]:
    """The resolved types of a dataclass's fields (ClassVars are not fields), with their
    `Annotated[…]` (the references), once per class; the IR text (text_types) reads them too.
    A field's type must resolve at run time (no name imported only under TYPE_CHECKING):
    tests/ir/test_refs.py resolves every IR record."""
    hints = typing.get_type_hints(cls, include_extras=True)
    return {f.name: hints[f.name] for f in dataclasses.fields(cls)}


def shape_of(hint: Any) -> Shape:
    """The shape of one resolved type: which parts of a value of it are references or records."""
    origin, args = get_origin(hint), get_args(hint)
    if origin is Annotated:
        ref = next((m for m in hint.__metadata__ if isinstance(m, Ref)), None)
        return ("ref", ref) if ref is not None else shape_of(args[0])
    if hint is Any:  # a value whose type the record does not say: look at it
        return ("record",)
    if origin in (Union, types.UnionType):
        found = {shape for arg in args if (shape := shape_of(arg)) is not None}
        if len(found) > 1:
            raise TypeError(f"{hint} declares different things in one union: {sorted(map(str, found))}")
        return found.pop() if found else None
    if origin is tuple and args and args[-1] is not Ellipsis:
        items = tuple(shape_of(arg) for arg in args)
        return ("items", items) if any(s is not None for s in items) else None
    if origin in _SEQUENCES:
        inner = shape_of(args[0]) if args else None
        return ("seq", inner) if inner is not None else None
    if origin in _MAPPINGS and len(args) == 2:
        key, value = shape_of(args[0]), shape_of(args[1])
        return ("map", key, value) if key is not None or value is not None else None
    if hasattr(hint, "__supertype__"):  # NewType
        return shape_of(hint.__supertype__)
    if isinstance(hint, type) and dataclasses.is_dataclass(hint) and _holds_refs(hint):
        return ("record",)
    return None


@functools.cache
def _holds_refs(cls: type) -> bool:
    """Whether a record of this class may hold a reference: it declares one, or a record it
    may hold does (records may hold each other in a circle: a mesh's ops hold shapes)."""
    seen: set[type] = set()
    todo = [cls]
    while todo:
        record = todo.pop()
        if record in seen:
            continue
        seen.add(record)
        for name, hint in type_hints(record).items():
            if (record.__name__, name) in FREE_DATA or _declares(hint, todo):
                return True
    return False


def _declares(hint: Any, records: list[type]) -> bool:
    """Whether a type declares a reference itself (or is Any); adds the records in it to
    `records`."""
    if get_origin(hint) is Annotated and any(isinstance(m, Ref) for m in hint.__metadata__):
        return True
    if hint is Any:
        return True
    if hasattr(hint, "__supertype__"):
        return _declares(hint.__supertype__, records)
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        records.append(hint)
    return any(_declares(arg, records) for arg in get_args(hint) if arg is not Ellipsis)


def shapes(cls: type) -> tuple[tuple[str, Shape], ...]:
    """The fields of a record class that hold references or records, with their shapes."""
    found = _SHAPES.get(cls)
    if found is None:
        found = tuple((name, shape) for name, hint in type_hints(cls).items()
                      if (shape := _free((cls.__name__, name)) or shape_of(hint)) is not None)
        _SHAPES[cls] = found
    return found


def _free(field: tuple[str, str]) -> Shape:
    patterns = FREE_DATA.get(field)
    if not patterns:
        return None
    return ("free", tuple((tuple(pattern.split("/")), ref) for pattern, ref in patterns))


def _children(value: Any) -> list[tuple[Any, Any]]:
    """(key or position, item) of a mapping or sequence in free data; [] for anything else."""
    if isinstance(value, Mapping):
        return list(value.items())
    if isinstance(value, list | tuple):
        return list(enumerate(value))
    return []


def refs(obj: Any, path: str = "") -> Iterator[tuple[Ref, str, str]]:
    """(declaration, name, field path) of every reference in a record, nested ones too; the path
    is `field`, `field/i` for an item, `field/key` for a mapping's key or value."""
    for name, shape in shapes(type(obj)):
        yield from _refs(getattr(obj, name), shape, f"{path}{name}")


def _refs(value: Any, shape: Shape, path: str) -> Iterator[tuple[Ref, str, str]]:
    if value is None or shape is None:
        return
    tag = shape[0]
    if tag == "ref":
        if isinstance(value, str) and value:  # "" names nothing (a default: none, or all)
            yield shape[1], value, path
    elif tag == "free":
        for parts, ref in shape[1]:
            yield from _free_refs(value, parts, ref, path)
    elif tag == "items":
        for i, (item, inner) in enumerate(zip(value, shape[1], strict=False)):
            yield from _refs(item, inner, f"{path}/{i}")
    elif tag == "seq":
        for i, item in enumerate(value):
            yield from _refs(item, shape[1], f"{path}/{i}")
    elif tag == "map":
        for key, item in value.items():
            yield from _refs(key, shape[1], f"{path}/{key}")
            yield from _refs(item, shape[2], f"{path}/{key}")
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        yield from refs(value, f"{path}/")
    elif isinstance(value, tuple | list):
        for i, item in enumerate(value):
            yield from _refs(item, shape, f"{path}/{i}")
    elif isinstance(value, Mapping):
        for key, item in value.items():
            yield from _refs(item, shape, f"{path}/{key}")


def _free_refs(value: Any, parts: tuple[str, ...], ref: Ref, path: str) -> Iterator[tuple[Ref, str, str]]:
    if not parts:
        if isinstance(value, str) and value:
            yield ref, value, path
        return
    for key, item in _children(value):
        if fnmatchcase(str(key), parts[0]):
            yield from _free_refs(item, parts[1:], ref, f"{path}/{key}")


def renamed(obj: Any, rename: Rename, only: tuple[str, ...] = ()) -> Any:
    """The record with every declared reference and name renamed (the same object when none
    changed); only: these fields of it (all when empty)."""
    changes = {}
    for name, shape in shapes(type(obj)):
        if only and name not in only:
            continue
        old = getattr(obj, name)
        new = _renamed(old, shape, rename)
        if new is not old:
            changes[name] = new
    return dataclasses.replace(obj, **changes) if changes else obj


def _renamed(value: Any, shape: Shape, rename: Rename) -> Any:
    if value is None or shape is None:
        return value
    tag = shape[0]
    if tag == "ref":
        if not isinstance(value, str) or not value:
            return value
        new = rename(shape[1].kinds, value)
        return value if new == value else new
    if tag == "free":
        for parts, ref in shape[1]:
            value = _free_map(value, parts, lambda name, ref=ref: rename(ref.kinds, name))
        return value
    if tag == "items":
        items = [_renamed(item, inner, rename) for item, inner in zip(value, shape[1], strict=False)]
        items += value[len(items):]
        return value if all(a is b for a, b in zip(items, value, strict=True)) else type(value)(items)
    if tag == "seq":
        items = [_renamed(item, shape[1], rename) for item in value]
        return value if all(a is b for a, b in zip(items, value, strict=True)) else type(value)(items)
    if tag == "map":
        pairs = [(_renamed(k, shape[1], rename), _renamed(v, shape[2], rename)) for k, v in value.items()]
        same = all(k is k0 and v is v0 for (k, v), (k0, v0) in zip(pairs, value.items(), strict=True))
        return value if same else dict(pairs)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return renamed(value, rename)
    if isinstance(value, tuple | list):
        items = [_renamed(item, shape, rename) for item in value]
        return value if all(a is b for a, b in zip(items, value, strict=True)) else type(value)(items)
    if isinstance(value, Mapping):
        pairs = [(k, _renamed(v, shape, rename)) for k, v in value.items()]
        same = all(v is v0 for (_, v), v0 in zip(pairs, value.values(), strict=True))
        return value if same else dict(pairs)
    return value



_DROPPED = object()  # what _free_map's `changed` gives for a name dropped from its list


def _free_map(value: Any, parts: tuple[str, ...], change: Callable[[str], str | None]) -> Any:
    """Free data with each name at `parts` changed (None: the name is dropped from its list;
    elsewhere it stays); the same object where nothing changed."""
    if not parts:
        return value
    last = len(parts) == 1

    def changed(item: Any) -> Any:
        if not last:
            return _free_map(item, parts[1:], change)
        if not isinstance(item, str) or not item:
            return item
        new = change(item)
        return _DROPPED if new is None else item if new == item else new

    if isinstance(value, Mapping):
        out = {k: changed(v) if fnmatchcase(str(k), parts[0]) else v for k, v in value.items()}
        if all(out[k] is v for k, v in value.items()):
            return value
        return {k: (value[k] if v is _DROPPED else v) for k, v in out.items()}  # a value is not dropped
    if isinstance(value, list | tuple):
        items = [changed(v) if fnmatchcase(str(i), parts[0]) else v for i, v in enumerate(value)]
        if all(a is b for a, b in zip(items, value, strict=True)):
            return value
        return type(value)(item for item in items if item is not _DROPPED)
    return value


def _ref_kind(ref: Ref, name: str, joints: Any) -> str:
    """The kind a reference names: its one kind, else a joint when `joints` has the name."""
    return ref.kinds[0] if len(ref.kinds) == 1 or name in joints else ref.kinds[-1]


def names_only(obj: Any, kept: Callable[[str, str], bool], joints: Any = (),
               only: tuple[str, ...] = ()) -> bool:
    """Whether every name the record uses (not the ones it defines) is kept: kept(kind, name).
    joints: the joint names, for a reference that may name a joint or a link. only: these
    fields of it (all when empty)."""
    return all(kept(_ref_kind(ref, name, joints), name) for ref, name, path in refs(obj)
               if not ref.defines and (not only or path.split("/", 1)[0] in only))


def pruned(obj: Any, gone: Callable[[str, str], bool], field: str) -> Any:
    """The record whose free data in `field` no longer lists the names that are gone:
    gone(kind, name) (a name outside a list stays)."""
    shape = dict(shapes(type(obj))).get(field)
    if shape is None or shape[0] != "free":
        return obj
    value = old = getattr(obj, field)
    for parts, ref in shape[1]:
        value = _free_map(value, parts,
                          lambda name, ref=ref: None if gone(_ref_kind(ref, name, ()), name) else name)
    return obj if value is old else dataclasses.replace(obj, **{field: value})
