"""Type hints of the IR dataclasses → the registry and the value checks of the textual IR.

`registry()` collects every dataclass reachable from the field hints of Program and of
the ops in OPS (so a new op or field needs no change here); `Converter` turns parsed
value nodes into Python values of a field's hinted type, recording an error per bad
value. It knows only type hints: no op-specific rules.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import types
from collections import abc
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path, PurePath
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from mpc.core.diagnostics import did_you_mean
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.ops import OPS, import_all
from mpc.ir.refs import type_hints

import_all()  # the IR text names every op: import the op modules `mpc check` does not need

SEQUENCES = (tuple, list, frozenset, set, abc.Sequence, abc.MutableSequence, abc.Set, abc.MutableSet,
             abc.Collection, abc.Iterable)
MAPPINGS = (dict, abc.Mapping, abc.MutableMapping, types.MappingProxyType)
BAD: Any = object()  # a value that failed its check (its errors are recorded)
_NO: Any = object()  # a literal that does not fit the hint (nothing recorded yet)


# Value nodes: what the IR transformer returns and the converter consumes. span: in the IR text.

@record(slots=True)
class Scalar:
    """A literal: none, true/false, an int, a float or a string."""

    value: bool | int | float | str | None
    span: Span


@record(slots=True)
class ListNode:
    """`[a, b]`: a tuple, list or set, as the field's hint says."""

    items: tuple[Node, ...]
    span: Span


@record(slots=True)
class MapNode:
    """`{key: value, …}`, keys and values in written order."""

    pairs: tuple[tuple[Node, Node], ...]
    span: Span


@record(slots=True)
class FieldNode:
    """`name=value`, in a record or in a call; name_span: where the name is."""

    name: str
    value: Node
    name_span: Span


@record(slots=True)
class Call:
    """`path("…")`, `span("f", 1, 2, 3, 4)` or `TypeName(field=value, …)`."""

    name: str
    args: tuple[Node, ...]
    fields: tuple[FieldNode, ...]
    span: Span
    name_span: Span


Node = Scalar | ListNode | MapNode | Call


@dataclass(frozen=True, eq=False)  # hashed by identity: printing caches per registry
class Registry:
    """The classes the IR text can name.

    program, input: the Program and Input classes. exports: export class by its `type`.
    ops: OPS as it was when the registry was built. types: nested dataclasses by class name.
    """

    program: type
    input: type
    exports: Mapping[str, type]
    ops: Mapping[str, type]
    types: Mapping[str, type]


def registry() -> Registry:
    """The registry for the ops registered now (rebuilt when OPS changes)."""
    return _registry(tuple(OPS.items()))


@functools.lru_cache(maxsize=8)
def _registry(ops: tuple[tuple[str, type], ...]) -> Registry:
    from mpc.ir.program import Program

    top = field_hints(Program)
    input_cls = get_args(top["inputs"])[1]
    exports: dict[str, type] = {}
    for cls in union_arms(get_args(top["exports"])[0]):
        default = {f.name: f.default for f in dataclasses.fields(cls)}.get("type")
        if not isinstance(default, str) or default in exports:
            raise TypeError(f"export class {cls.__name__} needs a unique `type` default")
        exports[default] = cls
    found: dict[str, type] = {}
    for root in (Program, *(cls for _, cls in ops)):
        _collect(root, found)
    return Registry(Program, input_cls, exports, dict(ops), found)


def _collect(hint: Any, found: dict[str, type]) -> None:
    """Add every dataclass in `hint` (and in its fields' hints, recursively) to `found`."""
    hint = unwrap(hint)
    if get_origin(hint) is Literal:
        return
    if isinstance(hint, type) and dataclasses.is_dataclass(hint) and hint is not Span:
        known = found.get(hint.__name__)
        if known is hint:
            return
        if known is not None:  # the text names types by class name alone
            raise TypeError(f"two IR dataclasses are named {hint.__name__}: "
                            f"{known.__module__} and {hint.__module__}")
        found[hint.__name__] = hint
        for sub in field_hints(hint).values():
            _collect(sub, found)
    for arg in get_args(hint):
        if arg is not Ellipsis:
            _collect(arg, found)


@functools.cache
def field_hints(cls: type) -> dict[str, Any]:
    """A dataclass's init fields → their resolved type hints (ClassVars are not fields); the
    declared references' `Annotated[…]` stay (`unwrap` sees through them), so that the IR text
    and ir/refs.py resolve each class once."""
    hints = type_hints(cls)
    return {f.name: hints[f.name] for f in dataclasses.fields(cls) if f.init}


def unwrap(hint: Any) -> Any:
    """NewType → its base type, `Annotated[T, …]` → T; Any stays Any."""
    while True:
        if hasattr(hint, "__supertype__"):
            hint = hint.__supertype__
        elif get_origin(hint) is Annotated:
            hint = get_args(hint)[0]
        else:
            return hint


def union_arms(hint: Any) -> tuple[Any, ...]:
    """The members of `X | Y` (or `(hint,)` for a non-union)."""
    return get_args(hint) if get_origin(hint) in (Union, types.UnionType) else (hint,)


def describe(hint: Any) -> str:
    """A type hint, for messages: `a number or none`."""
    hint, origin, args = unwrap(hint), get_origin(unwrap(hint)), get_args(unwrap(hint))
    if origin in (Union, types.UnionType):
        return " or ".join(describe(a) for a in args)
    if origin is Literal:
        shown = [json.dumps(a) if isinstance(a, str) else str(a) for a in args]
        return shown[0] if len(shown) == 1 else "one of " + ", ".join(shown)
    if origin is tuple and args and args[-1] is not Ellipsis:
        return f"a list of {len(args)} items"
    if (origin or hint) in SEQUENCES:
        return "a list"
    if (origin or hint) in MAPPINGS:
        return "a mapping"
    named = {type(None): "none", bool: "true or false", int: "an integer", float: "a number",
             str: "a string", Span: "span(…)"}
    if hint in named:
        return named[hint]
    if isinstance(hint, type) and issubclass(hint, PurePath):
        return 'path("…")'
    return f"{hint.__name__}(…)" if isinstance(hint, type) else str(hint)


def describe_node(node: Node) -> str:
    """A parsed value, for messages: `"abc"`, `3`, `a list of 2 items`, `Pose(…)`."""
    if isinstance(node, Scalar):
        v = node.value
        if v is None or isinstance(v, bool):
            return {None: "none", True: "true", False: "false"}[v]
        text = json.dumps(v, ensure_ascii=False) if isinstance(v, str) else repr(v)
        return text if len(text) <= 40 else text[:37] + "…"
    if isinstance(node, ListNode):
        return f"a list of {len(node.items)} item{'' if len(node.items) == 1 else 's'}"
    return "a mapping" if isinstance(node, MapNode) else f"{node.name}(…)"


@record(slots=True)
class Where:
    """Where a value sits, for messages: owner `op 'move'`, path `pose.xyz[1]`."""

    owner: str
    path: str
    key: bool = False  # a key of the mapping at `path`, rather than the value at `path`

    def __str__(self) -> str:
        return f"{'a key of ' if self.key else ''}field '{self.path}' of {self.owner}"

    def sub(self, suffix: str) -> Where:
        return Where(self.owner, self.path + suffix)


@record(frozen=False)
class Converter:
    """Value nodes → typed values by the type hints; errors go to `errors` as (span, code, message)."""

    reg: Registry
    errors: list[tuple[Span, str, str]] = field(default_factory=list)

    def error(self, span: Span, code: str, message: str) -> Any:
        self.errors.append((span, code, message))
        return BAD

    def fields(self, cls: type, nodes: tuple[FieldNode, ...], owner: str, span: Span,
               given: Mapping[str, Any] | None = None) -> dict[str, Any] | None:
        """`name=value` nodes (plus values `given` by the record's syntax) → checked init kwargs."""
        hints, kwargs = field_hints(cls), dict(given or {})
        before = len(self.errors)
        seen: set[str] = set()
        for f in nodes:
            if f.name in seen:
                self.error(f.name_span, "E0234", f"{owner} has field '{f.name}' twice")
            elif f.name not in hints:
                self.error(f.name_span, "E0231", f"{owner} has no field '{f.name}'"
                           f"{did_you_mean(f.name, set(hints))}")
            else:
                kwargs[f.name] = self.value(f.value, hints[f.name], Where(owner, f.name))
            seen.add(f.name)
        for f in dataclasses.fields(cls):
            if f.init and f.name not in kwargs and f.default is dataclasses.MISSING \
                    and f.default_factory is dataclasses.MISSING:
                self.error(span, "E0233", f"{owner} is missing required field '{f.name}'")
        ok = len(self.errors) == before
        return kwargs if ok else None

    def build(self, cls: type, kwargs: dict[str, Any], owner: str, span: Span) -> Any:
        """cls(**kwargs); a check in the class's __post_init__ becomes an E0234 at `span`."""
        try:
            return cls(**kwargs)
        except (TypeError, ValueError) as e:
            return self.error(span, "E0234", f"{owner} cannot be built: {e}")

    def value(self, node: Node, hint: Any, at: Where) -> Any:
        """One value node → a value of type `hint`, or BAD after recording why not."""
        hint = unwrap(hint)
        origin, args = get_origin(hint), get_args(hint)
        if hint is Any or hint is object:
            return self._untyped(node, at)
        if origin in (Union, types.UnionType):
            return self._union(node, args, at)
        if isinstance(node, Call):
            return self._call(node, hint, at)
        if origin is Literal:
            v = node.value if isinstance(node, Scalar) else BAD
            if any(type(a) is type(v) and a == v for a in args):
                return v
        elif (origin or hint) in SEQUENCES:
            if isinstance(node, ListNode):
                return self._sequence(node, origin or hint, args, at)
        elif (origin or hint) in MAPPINGS:
            if isinstance(node, MapNode):
                return self._mapping(node, args or (Any, Any), at)
        elif isinstance(node, Scalar):
            value = self._scalar(node, hint, at)
            if value is not _NO:
                return value
        return self.error(node.span, "E0232", f"{at} must be {describe(hint)}, got {describe_node(node)}")

    def _scalar(self, node: Scalar, hint: Any, at: Where) -> Any:
        """A literal as a none, bool, int, float or str field (or a subclass); _NO if it does not fit."""
        v = node.value
        if hint is type(None) or hint is bool:
            return v if (v is None if hint is type(None) else isinstance(v, bool)) else _NO
        if v is None or isinstance(v, bool) or not isinstance(hint, type):
            return _NO
        if hint is float and isinstance(v, int | float):
            try:
                return float(v)  # an int written for a float field
            except OverflowError:
                return self.error(node.span, "E0232", f"{at} is out of range: {describe_node(node)}")
        if type(v) is hint:
            return v
        for base, accepted in ((str, str), (int, int), (float, int | float)):
            if issubclass(hint, base) and isinstance(v, accepted):
                try:
                    return hint(v)  # a subclass: a str-based name type, an IntEnum, …
                except (TypeError, ValueError) as e:
                    return self.error(node.span, "E0232", f"{at}: {e}")
        return _NO

    def _union(self, node: Node, arms: tuple[Any, ...], at: Where) -> Any:
        if isinstance(node, Call):
            cls = self._resolve(node)
            if cls is None:
                return BAD
            fitting = [a for a in arms if _accepts(a, cls)]
            if fitting:
                return self.value(node, fitting[0], at)
        else:
            shaped = []
            for arm in arms:
                trial = Converter(self.reg)
                value = trial.value(node, arm, at)
                if not trial.errors:
                    return value
                if _same_shape(arm, node):
                    shaped.append(arm)
            if len(shaped) == 1:  # report why the one arm of this shape did not fit
                return self.value(node, shaped[0], at)
        hint = Union[arms]  # noqa: UP007 - rebuilding a union from its arms
        return self.error(node.span, "E0232", f"{at} must be {describe(hint)}, got {describe_node(node)}")

    def _sequence(self, node: ListNode, origin: Any, args: tuple[Any, ...], at: Where) -> Any:
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(args) != len(node.items):
                return self.error(node.span, "E0232", f"{at} must be a list of {len(args)} items, "
                                                      f"got {describe_node(node)}")
            hints = args
        else:
            hints = (args[0] if args else Any,) * len(node.items)
        pairs = enumerate(zip(node.items, hints, strict=True))
        items = [self.value(n, h, at.sub(f"[{i}]")) for i, (n, h) in pairs]
        if any(v is BAD for v in items):
            return BAD
        kind = {list: list, abc.MutableSequence: list, frozenset: frozenset, abc.Set: frozenset,
                set: set, abc.MutableSet: set}.get(origin, tuple)
        return kind(items)

    def _mapping(self, node: MapNode, args: tuple[Any, ...], at: Where) -> Any:
        out: dict[Any, Any] = {}
        before = len(self.errors)
        for k, v in node.pairs:
            key = self.value(k, args[0], Where(at.owner, at.path, key=True))
            if key is not BAD and key in out:
                self.error(k.span, "E0234", f"{at} has key {describe_node(k)} twice")
            value = self.value(v, args[1], at.sub(f"[{describe_node(k)}]"))
            if key is not BAD and value is not BAD:
                out.setdefault(key, value)
        ok = len(self.errors) == before
        return out if ok else BAD

    def _resolve(self, node: Call) -> type | None:
        """The class a call names (Path, Span or a registered dataclass), or None after E0231."""
        special = {"path": Path, "span": Span}
        cls = special.get(node.name) or self.reg.types.get(node.name)
        if cls is None:
            self.error(node.name_span, "E0231", f"unknown type '{node.name}'"
                       f"{did_you_mean(node.name, set(self.reg.types) | set(special))}")
        return cls

    def _call(self, node: Call, hint: Any, at: Where) -> Any:
        cls = self._resolve(node)
        if cls is None:
            return BAD
        if not (hint is Any or hint is object or _accepts(hint, cls)):
            return self.error(node.span, "E0232", f"{at} must be {describe(hint)}, got {node.name}(…)")
        if cls is Path:
            if len(node.args) != 1 or node.fields or not _is_str(node.args[0]):
                return self.error(node.span, "E0232", f"{at}: path(…) takes one string")
            return Path(node.args[0].value)  # type: ignore[union-attr, arg-type]
        if cls is Span:
            ok = not node.fields and 1 <= len(node.args) <= 5 and _is_str(node.args[0]) and all(
                isinstance(a, Scalar) and type(a.value) is int for a in node.args[1:])
            if not ok:
                return self.error(node.span, "E0232", f"{at}: span(…) takes a file and up to 4 "
                                                      "integers: line, col, end_line, end_col")
            return Span(*(a.value for a in node.args))  # type: ignore[union-attr]
        owner = f"{cls.__name__}(…) in {at}"
        if node.args:
            return self.error(node.args[0].span, "E0232", f"{owner} takes field=value arguments")
        kwargs = self.fields(cls, node.fields, owner, node.span)
        return BAD if kwargs is None else self.build(cls, kwargs, owner, node.span)

    def _untyped(self, node: Node, at: Where) -> Any:
        """A value where the hint says nothing (`object`, `Any`): lists become tuples."""
        if isinstance(node, Scalar):
            return node.value
        if isinstance(node, ListNode):
            items = [self._untyped(n, at.sub(f"[{i}]")) for i, n in enumerate(node.items)]
            return BAD if any(v is BAD for v in items) else tuple(items)
        if isinstance(node, MapNode):
            return self._mapping(node, (Any, Any), at)
        return self._call(node, Any, at)


def _is_str(node: Node) -> bool:
    return isinstance(node, Scalar) and isinstance(node.value, str)


def _accepts(hint: Any, cls: type) -> bool:
    """Whether a value of class `cls` fits `hint` (a class, or a union of classes)."""
    hint = unwrap(hint)
    if get_origin(hint) in (Union, types.UnionType):
        return any(_accepts(a, cls) for a in get_args(hint))
    return hint is Any or hint is object or (isinstance(hint, type) and issubclass(cls, hint))


def _same_shape(hint: Any, node: Node) -> bool:
    """Whether `node` is the kind of value (list or mapping) that `hint` asks for."""
    origin = get_origin(hint) or hint
    return (isinstance(node, ListNode) and origin in SEQUENCES) or \
        (isinstance(node, MapNode) and origin in MAPPINGS)
