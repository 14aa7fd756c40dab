"""The values of a kept build (compiler/build_cache.py) as JSON, and back: a program, its
robot and diagnostics, written so that reading them runs no code the cache could choose.

A kept build lives in `$MPC_CACHE_DIR`, which anyone who can write there may change (a CI
cache shared with merge-request pipelines). Pickle would run whatever the entry names; this
form holds data only, and its reader makes nothing but values of mpc's own records.

A value is JSON's own (null, true/false, an int, a float: NaN and the infinities as Python's
json writes them, a string), a list (a JSON array), or an object of one member whose name says
what it is:

    {"t": [v…]}   a tuple             {"s": [v…]}              a frozenset
    {"d": [k, v, k, v…]}  a dict      {"p": "a/b"}             a path
    {"e": ["mpc.m:Enum", value]}      a member of an enum
    {"r": ["mpc.m:Class", v…]}        a record (core/record.py), one value per field, in order

Reading is strict (`loads` raises BadValue): a class is named by its module and name, and must
be a record class or an enum of a module under `mpc.core` or `mpc.ir`, defined there; a record
gets exactly one value per field, set as unpickling sets them (no `__init__` runs); any other
object (an unknown tag, a class of another module) is refused. json's parser makes every
scalar and list; Python sees each object once (`object_hook`), which keeps reading a robot of
a hundred links within a few milliseconds.
"""

from __future__ import annotations

import functools
import importlib
import json
import re
import sys
from collections.abc import Callable
from enum import Enum
from pathlib import PosixPath, PurePath, PurePosixPath
from typing import Any

from mpc.core.record import from_values, is_record, record_of, record_values

# Where the classes of kept values live: the IR and the ground floor (spans, diagnostics).
_MODULE = re.compile(r"mpc\.(core|ir)(\.[a-z_][a-z0-9_]*)*")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class BadValue(ValueError):
    """What was read is not a value this module writes."""


def dumps(value: Any, paths: list[PurePath] | None = None) -> bytes:
    """`value` as one line of JSON; each path met is appended to `paths`. Raises TypeError for
    a value of a type that is not kept (the build is then not kept)."""
    plain = _Encoder([] if paths is None else paths).encode(value)
    return json.dumps(plain, separators=(",", ":"), check_circular=False).encode()


def loads(data: bytes | str) -> Any:
    """The value `data` (what `dumps` wrote) stands for; raises BadValue when it is not one."""
    try:
        return json.loads(data, object_hook=_Decoder().object)
    except RecursionError:
        raise BadValue("values nested too deeply") from None
    except BadValue:
        raise
    except ValueError as e:  # not JSON (a pickle, say: it is never unpickled)
        raise BadValue(f"not JSON ({str(e)[:60]})") from None


_SCALARS = frozenset({str, int, float, bool, type(None)})  # written as they are


class _Encoder:
    """Each container's items are looked at in place when they are scalars (most are: names,
    numbers), not through a call: that call per value was most of the time of keeping a build."""

    def __init__(self, paths: list[PurePath]) -> None:
        self.paths = paths
        self.by_type: dict[type, Callable[[Any], Any]] = {
            tuple: self._tuple, list: self._list, frozenset: self._frozenset, dict: self._dict,
            PosixPath: self._path, PurePosixPath: self._path,
        }

    def encode(self, value: Any) -> Any:
        cls = type(value)
        if cls in _SCALARS:
            return value
        if cls is tuple:  # the most frequent container: written here, without a call
            encode = self.encode
            return {"t": [v if type(v) in _SCALARS else encode(v) for v in value]}
        how = self.by_type.get(cls)
        if how is None:
            how = self._how(cls)
        return how(value)

    def _items(self, values: Any) -> list[Any]:
        encode = self.encode
        return [v if type(v) in _SCALARS else encode(v) for v in values]

    def _how(self, cls: type) -> Callable[[Any], Any]:
        kept = record_of(cls) or cls  # a lazy twin (a LazySpan) is kept as the record it finds
        tag = f"{kept.__module__}:{kept.__qualname__}"
        if not _MODULE.fullmatch(kept.__module__) or not _NAME.fullmatch(kept.__qualname__):
            raise TypeError(f"a value of type {tag} is not kept")
        how: Callable[[Any], Any]
        encode = self.encode
        if is_record(kept):
            def how(obj: Any) -> Any:
                out = [tag]
                out += [v if type(v) in _SCALARS else encode(v) for v in record_values(obj)]
                return {"r": out}
        elif issubclass(kept, Enum):
            def how(member: Any) -> Any:
                return {"e": [tag, encode(member.value)]}
        else:
            raise TypeError(f"a value of type {tag} is not kept")
        self.by_type[cls] = how
        return how

    def _tuple(self, value: tuple[Any, ...]) -> Any:
        return {"t": self._items(value)}

    def _list(self, value: list[Any]) -> Any:
        return self._items(value)

    def _frozenset(self, value: frozenset[Any]) -> Any:
        return {"s": self._items(value)}

    def _dict(self, value: dict[Any, Any]) -> Any:
        encode, out = self.encode, []
        for k, v in value.items():
            out += (encode(k), encode(v))
        return {"d": out}

    def _path(self, value: PurePath) -> Any:
        self.paths.append(value)
        return {"p": str(value)}


class _Decoder:
    """json's `object_hook`: each object, its members already read, to the value it stands for."""

    def __init__(self) -> None:
        self.classes: dict[str, type] = {}
        self.records: dict[str, Callable[[list[Any]], Any]] = {}  # tag → from_values of its class
        self.by_tag: dict[str, Callable[[Any], Any]] = {
            "r": self._record, "t": self._tuple, "s": self._frozenset, "d": self._dict,
            "p": self._path, "e": self._enum}

    def object(self, obj: dict[str, Any]) -> Any:
        if len(obj) != 1:
            raise BadValue(f"an object of {len(obj)} members")
        [(tag, payload)] = obj.items()
        if type(payload) is list:  # the most frequent first: tuples, records of a known class
            if tag == "t":
                return tuple(payload)
            if tag == "r" and payload:
                build = self.records.get(payload[0])
                if build is not None:
                    try:
                        return build(payload[1:])
                    except ValueError:
                        raise BadValue(f"not one value for each field of '{payload[0]}'") from None
        how = self.by_tag.get(tag)
        if how is None:
            raise BadValue(f"an object tagged {tag[:20]!r}")
        return how(payload)

    def _record(self, payload: Any) -> Any:
        if type(payload) is not list or not payload:
            raise BadValue("a record without its class")
        cls = self._class(payload[0])
        if not is_record(cls):
            raise BadValue(f"'{payload[0]}' is not a record")
        self.records[payload[0]] = functools.partial(from_values, cls)
        try:
            return from_values(cls, payload[1:])
        except ValueError:
            raise BadValue(f"not one value for each field of '{payload[0]}'") from None

    def _tuple(self, payload: Any) -> Any:
        if type(payload) is not list:
            raise BadValue("a tuple that is no array")
        return tuple(payload)

    def _frozenset(self, payload: Any) -> Any:
        if type(payload) is not list:
            raise BadValue("a set that is no array")
        try:
            return frozenset(payload)
        except TypeError:
            raise BadValue("an unhashable member of a set") from None

    def _dict(self, payload: Any) -> Any:
        if type(payload) is not list or len(payload) % 2:
            raise BadValue("a dict that is no array of keys and values")
        try:
            return dict(zip(payload[::2], payload[1::2], strict=True))
        except TypeError:
            raise BadValue("an unhashable key of a dict") from None

    def _path(self, payload: Any) -> Any:
        if type(payload) is not str or "\0" in payload:
            raise BadValue("a path that is no string")
        return PosixPath(payload)

    def _enum(self, payload: Any) -> Any:
        if type(payload) is not list or len(payload) != 2:
            raise BadValue("an enum member without its class and value")
        cls = self._class(payload[0])
        if not issubclass(cls, Enum):
            raise BadValue(f"'{payload[0]}' is not an enum")
        try:
            return cls(payload[1])
        except (ValueError, TypeError):
            raise BadValue(f"no member of '{payload[0]}' has the value {payload[1]!r}") from None

    def _class(self, tag: Any) -> type:
        cls = self.classes.get(tag) if type(tag) is str else None
        if cls is not None:
            return cls
        module, _, name = tag.partition(":") if type(tag) is str else ("", "", "")
        if not _MODULE.fullmatch(module) or not _NAME.fullmatch(name):
            raise BadValue(f"{str(tag)[:80]!r} names no class of mpc's IR")
        if module not in sys.modules:
            try:
                importlib.import_module(module)  # one of mpc's own modules, never another's
            except ImportError:
                raise BadValue(f"'{module}' is no module of mpc") from None
        found = getattr(sys.modules[module], name, None)
        if not isinstance(found, type) or found.__module__ != module:  # not one imported there
            raise BadValue(f"'{tag}' names no class of that module")
        self.classes[tag] = found
        return found
