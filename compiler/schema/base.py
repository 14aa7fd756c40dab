"""Located YAML data → typed AST nodes, every problem a located diagnostic.

The language is declared as annotated classes (`class Transform(Node): xyz: Vec3 = …`);
this module reads those declarations and validates the data of a document against them
in one walk, building the nodes as it goes. It is ours, not pydantic's, because `mpc
check` starts cold in every editor save: pydantic alone costs more to import and to build
the schema than the whole check may take (issue 3: 250 ms).

Declarations: a field is an annotation, optionally with a default or `Field(default,
alias=…, min_length=…, max_length=…)`; `Field(min_length=…)` also stands inside
`Annotated[…]`. `Before(fn)` reshapes a value before it is checked (one name for a list
of names), `After(fn)` checks it further (raising ValueError with the message),
`JsonSchema({…})` says how `mpc schema` describes a type. A node's `problem()` checks
the node as a whole.

Three kinds of mapping appear in the language:
- closed sections (most of them): every key is declared; others are errors;
- sections keyed by names (`frames`, `joints`, …): declared `$keys`, and any other key
  is an entry named after a link, joint or collision (`ENTRIES`);
- annotated entries: declared keys plus free annotations that travel to SMURF
  (`ANNOTATIONS`); an annotation key close to a declared one is a warning, since it
  is most likely a typo of an operation.

Unions are told apart by the shape of the data: a mapping goes to the member that takes
mappings, a list to the one that takes lists, and a union of nodes by their `type`. One
mistake never hides the others: every problem is reported, and a bad entry of a list is
dropped from it rather than failing its neighbours.
"""

from __future__ import annotations

import inspect
import sys
import types
import typing
from collections.abc import Callable
from typing import Annotated, Any, ClassVar, Literal

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.span import Span
from mpc.core.yaml_source import Document, Path_

_REQUIRED: Any = object()


class Field:
    """A field's default, its key in the document (`alias`) and length bounds."""

    def __init__(self, default: Any = _REQUIRED, *, alias: str | None = None,
                 min_length: int | None = None, max_length: int | None = None) -> None:
        self.default, self.alias = default, alias
        self.min_length, self.max_length = min_length, max_length


class Before:
    """Reshape the value before it is checked."""

    def __init__(self, fn: Callable[[Any], Any]) -> None:
        self.fn = fn


class After:
    """Check the value further once its type is right; `fn` raises ValueError(message),
    reported as `code` (or the error's own `code` attribute)."""

    def __init__(self, fn: Callable[[Any], Any], code: str = "E0203") -> None:
        self.fn, self.code = fn, code


class JsonSchema:
    """How `mpc schema` describes the type, instead of what its shape would give."""

    def __init__(self, schema: dict[str, Any]) -> None:
        self.schema = schema


class _ExprMarker:
    def __repr__(self) -> str:
        return "EXPR"


EXPR = _ExprMarker()

# A number as users write it: 1.5, "2*pi", ["deg", 90]; evaluated by compiler/expr.py.
Expr = Annotated[Any, EXPR]
Vec3 = Annotated[list[Expr], Field(min_length=3, max_length=3)]


def str_or_list(value: Any) -> Any:
    """Many keys take one name or a list of names; the AST always holds a list."""
    return [value] if isinstance(value, str) else value


class NameTooLong(ValueError):
    code = "E0251"


# Names that become file or folder names in the output: a name, never a path out of it.
# mpc adds suffixes and extensions (`_relpath.urdf`, `_motors.yml`), hence less than 255.
NAME_BYTES = 200


def _path_name(value: str, folders: bool) -> None:
    from mpc.core.files import name_problem

    longest = max(len(part.encode("utf-8", "surrogatepass")) for part in value.split("/"))
    if longest > NAME_BYTES:
        raise NameTooLong(f"a name of {longest} bytes cannot name a file in the output; at most "
                          f"{NAME_BYTES} (file systems take 255, and mpc adds suffixes and extensions)")
    if why := name_problem(value, folders=folders):
        raise ValueError(f"cannot name a file in the output: {why}")


FileName = Annotated[str, After(lambda v: _path_name(v, False), "E0250")]
# A suffix may be empty; a relative path (`file_name: limits/arm.yml`) has folders.
FileSuffix = Annotated[str, After(lambda v: v == "" or _path_name(v, False), "E0250")]
RelativeName = Annotated[str, After(lambda v: _path_name(v, True), "E0250")]

OneOrMore = Annotated[list[str], Before(str_or_list),
                      JsonSchema({"anyOf": [{"type": "string"},
                                            {"type": "array", "items": {"type": "string"}}]})]


# -- nodes -----------------------------------------------------------------------------------

class FieldSpec:
    """One declared field of a node, resolved: its attribute name, type and default
    (`Node.fields` files it under its key in the document)."""

    __slots__ = ("default", "name", "type")

    def __init__(self, name: str, type_: Type, default: Any) -> None:
        self.name, self.type, self.default = name, type_, default

    @property
    def required(self) -> bool:
        return self.default is _REQUIRED

    def fresh_default(self) -> Any:
        d = self.default
        return list(d) if isinstance(d, list) else dict(d) if isinstance(d, dict) else d


class Node:
    """Base of every AST node: knows the document and path it was read from.

    SECTION: how messages name this part of the language.
    ENTRIES: for sections keyed by names, the type of each entry.
    ANNOTATIONS: whether undeclared keys are kept as free annotations.
    ALIASES: old spellings still accepted, mapped to the declared key.
    """

    SECTION: ClassVar[str] = ""
    ENTRIES: ClassVar[Any] = None
    ANNOTATIONS: ClassVar[bool] = False
    ALIASES: ClassVar[dict[str, str]] = {}
    TYPE_WORD: ClassVar[str] = "type"
    _doc: Document | None
    _path: Path_
    _extra: dict[str, Any]
    _given: frozenset[str]

    def problem(self) -> str | None:
        """What is wrong with the node as a whole, once its fields are right (None: nothing)."""
        return None

    @classmethod
    def fields(cls) -> dict[str, FieldSpec]:
        """The declared fields by key, in declaration order (resolved on first use)."""
        plan = cls.__dict__.get("_fields")
        if plan is None:
            plan = _resolve(cls)
            cls._fields = plan  # type: ignore[attr-defined]
        return plan

    @property
    def span(self) -> Span:
        """Where this node was written (the key that introduces it)."""
        assert self._doc is not None
        return self._doc.span(self._path)

    def value_span(self, key: str | int) -> Span:
        """Where the value of `key` was written (the node itself if the key is absent)."""
        assert self._doc is not None
        return self._doc.value_span((*self._path, key))

    def key_span(self, key: str | int) -> Span:
        assert self._doc is not None
        return self._doc.span((*self._path, key))

    @property
    def entries(self) -> dict[str, Any]:
        """The named entries of a section keyed by names (or the free annotations)."""
        return dict(self._extra)

    @property
    def given(self) -> frozenset[str]:
        """The names of the fields the document sets (the others hold their defaults)."""
        return self._given

    def to_data(self) -> dict[str, Any]:
        """Plain data: the fields that differ from their defaults, then the entries."""
        out = {f.name: _plain(getattr(self, f.name)) for f in self.fields().values()
               if f.required or getattr(self, f.name) != f.default}
        return out | {k: _plain(v) for k, v in self._extra.items()}

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(getattr(self, n) == getattr(other, n) for n in
                   (f.name for f in self.fields().values())) and self._extra == other._extra  # type: ignore[attr-defined]

    __hash__ = None  # type: ignore[assignment]  # equal by value, and lists are not hashable

    def __repr__(self) -> str:
        items = [f"{f.name}={getattr(self, f.name)!r}" for f in self.fields().values()]
        items += [f"{k!r}: {v!r}" for k, v in self._extra.items()]
        return f"{type(self).__name__}({', '.join(items)})"


def _plain(value: Any) -> Any:
    if isinstance(value, Node):
        return value.to_data()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _annotations(cls: type) -> dict[str, Any]:
    """The field annotations of a class and its bases, unevaluated (strings, under
    `from __future__ import annotations`), without class variables and private names."""
    out: dict[str, Any] = {}
    for c in reversed(cls.__mro__):
        for name, hint in inspect.get_annotations(c).items():
            if not name.startswith("_") and not str(hint).startswith(("ClassVar", "typing.ClassVar")):
                out[name] = (hint, c)
    return out


def _evaluate(hint: Any, owner: type) -> Any:
    """An annotation's value, in the module that declares it (typing.get_type_hints does the
    same for every annotation of the class, class variables too, at several times the cost)."""
    return eval(hint, vars(sys.modules[owner.__module__])) if isinstance(hint, str) else hint


def _resolve(cls: type[Node]) -> dict[str, FieldSpec]:
    out: dict[str, FieldSpec] = {}
    for name, (text, owner) in _annotations(cls).items():
        hint = _evaluate(text, owner)
        declared = getattr(cls, name, _REQUIRED)
        info = declared if isinstance(declared, Field) else Field(declared)
        type_ = compile_type(hint)
        if info.min_length is not None or info.max_length is not None:
            type_ = type_.bounded(info.min_length, info.max_length)
        key = info.alias or name
        out[key] = FieldSpec(name, type_, info.default)
    return out


# -- types -----------------------------------------------------------------------------------

BAD: Any = object()  # what a check returns for a value it reported


class Type:
    """A checked type: validates a value at a path, reporting problems through `Walk`."""

    wanted = "of another form"  # "must be <wanted>" in messages

    def fits(self, value: Any) -> bool:
        """Whether the value has this type's shape (which union member it is meant for)."""
        return not isinstance(value, list | dict)

    def exact(self, value: Any) -> bool:
        """Whether the value is of this type as it is, without conversion."""
        return self.fits(value)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        raise NotImplementedError

    def bounded(self, low: int | None, high: int | None) -> Type:
        raise TypeError(f"{self} takes no length bounds")


class AnyType(Type):
    def fits(self, value: Any) -> bool:
        return True

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        return value


class ExprType(Type):
    wanted = "a number or an expression"

    def fits(self, value: Any) -> bool:
        return not isinstance(value, dict)

    def exact(self, value: Any) -> bool:
        return not (isinstance(value, bool | dict) or value is None)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        return value if self.exact(value) else walk.wrong(self, value, path)


class StrType(Type):
    wanted = "a string"
    low: int | None = None

    def exact(self, value: Any) -> bool:
        return isinstance(value, str)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if not isinstance(value, str):
            return walk.wrong(self, value, path)
        if self.low and len(value) < self.low:
            return walk.fail(path, lambda key: f"'{key}' must not be empty")
        return value

    def bounded(self, low: int | None, high: int | None) -> Type:
        out = StrType()
        out.low = low
        return out


_TRUE = {"1", "on", "t", "true", "y", "yes"}
_FALSE = {"0", "off", "f", "false", "n", "no"}


class BoolType(Type):
    """true or false; also 0/1 and the words YAML 1.1 reads as booleans, when quoted."""

    wanted = "true or false"

    def exact(self, value: Any) -> bool:
        return isinstance(value, bool)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if isinstance(value, bool):
            return value
        if isinstance(value, int | float) and value in (0, 1):
            return bool(value)
        if isinstance(value, str) and value.lower() in _TRUE | _FALSE:
            return value.lower() in _TRUE
        return walk.wrong(self, value, path)


class IntType(Type):
    """An integer; also a float without a fraction and a string of digits."""

    wanted = "an integer"

    def exact(self, value: Any) -> bool:
        return isinstance(value, int) and not isinstance(value, bool)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if isinstance(value, int):
            return int(value)
        if isinstance(value, float) and value.is_integer():
            return int(value)
        if isinstance(value, str) and value.strip().lstrip("+-").isdigit():
            return int(value.strip())
        return walk.wrong(self, value, path)


class LiteralType(Type):
    def __init__(self, values: tuple[Any, ...]) -> None:
        self.values = values
        self.expected = _one_of([repr(v) for v in values])
        self.wanted = f"one of {self.expected}"

    def exact(self, value: Any) -> bool:
        return any(value == v and type(value) is type(v) for v in self.values)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if self.exact(value):
            return value
        options = {str(v) for v in self.values}
        return walk.fail(path, lambda key: f"'{key}' must be one of {self.expected}, got '{value}'"
                         + did_you_mean(str(value), options))


class ListType(Type):
    wanted = "a list"

    def __init__(self, item: Type, low: int | None = None, high: int | None = None) -> None:
        self.item, self.low, self.high = item, low, high

    def fits(self, value: Any) -> bool:
        return isinstance(value, list)

    def bounded(self, low: int | None, high: int | None) -> Type:
        return ListType(self.item, low, high)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if not isinstance(value, list):
            return walk.wrong(self, value, path)
        if self.high is not None and len(value) > self.high:
            return walk.fail(path, lambda key: f"'{key}' must have at most {_items(self.high)}, "
                                               f"got {len(value)}")
        out, failed, dropped = [], False, False
        for i, item in enumerate(value):
            got = self.item.check(item, (*path, i), walk)
            if got is DROP:
                dropped = True
            elif got is BAD:
                failed = True
            else:
                out.append(got)
        if failed:
            return BAD
        if self.low and len(out) < self.low:
            if dropped:  # the dropped entries are reported; "too short" would only repeat them
                return BAD
            if not value:
                return walk.fail(path, lambda key: f"'{key}' must not be empty")
            return walk.fail(path, lambda key: f"'{key}' must have at least {_items(self.low)}, "
                                               f"got {len(value)}")
        return out


class DictType(Type):
    wanted = "a mapping"

    def __init__(self, key: Type, value: Type, low: int | None = None) -> None:
        self.key, self.value, self.low = key, value, low

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict)

    def bounded(self, low: int | None, high: int | None) -> Type:
        return DictType(self.key, self.value, low)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if not isinstance(value, dict):
            return walk.wrong(self, value, path)
        if self.low and len(value) < self.low:
            return walk.fail(path, lambda key: f"'{key}' must not be empty")
        out, failed = {}, False
        for k, v in value.items():
            key, problems = walk.attempt(self.key, k, (*path, k))
            for problem in problems:  # a key's problem is shown at the key
                walk.error(walk.doc.span(walk.written((*path, k))), "E0203", problem)
            got = self.value.check(v, (*path, k), walk)
            if key is BAD or got is BAD or got is DROP:
                failed = True
            else:
                out[key] = got
        return BAD if failed else out


class NodeType(Type):
    wanted = "a mapping"

    def __init__(self, cls: type[Node]) -> None:
        self.cls = cls

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if not isinstance(value, dict):
            return walk.wrong(self, value, path)
        return walk.node(value, self.cls, path)


DROP: Any = object()  # an entry that is left out of its list (it is reported)


class TaggedType(Type):
    """A union of nodes told apart by their `type` literal (export entries)."""

    wanted = "a mapping"

    def __init__(self, members: list[type[Node]]) -> None:
        self.members = members
        self._tags: dict[str, type[Node]] | None = None

    @property
    def tags(self) -> dict[str, type[Node]]:
        """tag → node class (on first use: the members may contain this union)."""
        if self._tags is None:
            self._tags = {tag: m for m in self.members for tag in typing.get_args(_type_literal(m))}
        return self._tags

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if not isinstance(value, dict):
            return walk.wrong(self, value, path)
        kind = value.get("type")
        if isinstance(kind, str) and kind in self.tags:
            return walk.node(value, self.tags[kind], path)
        doc = walk.doc
        span = doc.value_span((*path, "type")) if "type" in value else doc.span(path)
        if kind is None:
            walk.error(span, "E0203", "this entry has no 'type'; one of "
                       + ", ".join(f"'{t}'" for t in self.tags) + " is required")
        else:
            word = next(iter(self.tags.values())).TYPE_WORD
            walk.error(span, "E0203", f"unknown {word} '{kind}'{did_you_mean(str(kind), set(self.tags))}",
                       hint=f"{word}s: " + ", ".join(self.tags))
        return DROP


class UnionType(Type):
    """Members told apart by the data's shape; scalars by the first member that takes them."""

    def __init__(self, members: list[Type]) -> None:
        self.members = members
        words = [m.wanted for m in members]
        self.wanted = " or ".join(dict.fromkeys(words))

    def fits(self, value: Any) -> bool:
        return any(m.fits(value) for m in self.members)

    def exact(self, value: Any) -> bool:
        return any(m.exact(value) for m in self.members)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        fitting = [m for m in self.members if m.fits(value)]
        if len(fitting) == 1 and isinstance(value, list | dict):  # its problems are the ones to show
            return fitting[0].check(value, path, walk)
        for m in fitting:
            if m.exact(value):
                return m.check(value, path, walk)
        for m in fitting:
            got, problems = walk.attempt(m, value, path)
            if not problems:
                return got
        return walk.wrong(self, value, path)


class OptionalType(Type):
    """`T | None`: nothing, or a T."""

    def __init__(self, inner: Type) -> None:
        self.inner = inner
        self.wanted = inner.wanted

    def fits(self, value: Any) -> bool:
        return value is None or self.inner.fits(value)

    def exact(self, value: Any) -> bool:
        return value is None or self.inner.exact(value)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        return None if value is None else self.inner.check(value, path, walk)

    def bounded(self, low: int | None, high: int | None) -> Type:
        return OptionalType(self.inner.bounded(low, high))


class Wrapped(Type):
    """A type with `Before`/`After` functions or its own JSON Schema."""

    def __init__(self, inner: Type, before: Callable[[Any], Any] | None,
                 after: After | None, json: dict[str, Any] | None) -> None:
        self.inner, self.before, self.after, self.json = inner, before, after, json
        self.wanted = inner.wanted

    def fits(self, value: Any) -> bool:
        return self.inner.fits(self.before(value) if self.before else value)

    def exact(self, value: Any) -> bool:
        return self.inner.exact(self.before(value) if self.before else value)

    def check(self, value: Any, path: Path_, walk: Walk) -> Any:
        if self.before:
            value = self.before(value)
        got = self.inner.check(value, path, walk)
        if self.after and got is not BAD and got is not DROP:
            try:
                self.after.fn(got)
            except ValueError as e:
                problem = str(e)
                return walk.fail(path, lambda key: f"'{key}': {problem}",
                                 getattr(e, "code", self.after.code))
        return got

    def bounded(self, low: int | None, high: int | None) -> Type:
        return Wrapped(self.inner.bounded(low, high), self.before, self.after, self.json)


_SCALARS: dict[Any, Callable[[], Type]] = {str: StrType, bool: BoolType, int: IntType, Any: AnyType}


def compile_type(tp: Any) -> Type:
    """The checked type of an annotation."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        inner, *meta = typing.get_args(tp)
        if EXPR in meta:
            out: Type = ExprType()
        else:
            out = compile_type(inner)
        for m in meta:
            if isinstance(m, Field):
                out = out.bounded(m.min_length, m.max_length)
        before = next((m.fn for m in meta if isinstance(m, Before)), None)
        after = next((m for m in meta if isinstance(m, After)), None)
        json = next((m.schema for m in meta if isinstance(m, JsonSchema)), None)
        return Wrapped(out, before, after, json) if before or after or json else out
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        members = [a for a in args if a is not type(None)]
        inner = compile_type(members[0]) if len(members) == 1 else _union(members)
        return OptionalType(inner) if type(None) in args else inner
    if origin is Literal:
        return LiteralType(typing.get_args(tp))
    if origin is list:
        (item,) = typing.get_args(tp)
        return ListType(compile_type(item))
    if origin is dict:
        key, value = typing.get_args(tp)
        return DictType(compile_type(key), compile_type(value))
    if isinstance(tp, type) and issubclass(tp, Node):
        return NodeType(tp)
    if tp in _SCALARS:
        return _SCALARS[tp]()
    raise TypeError(f"the schema cannot check {tp!r}")


def _union(members: list[Any]) -> Type:
    """Nodes with a `type` literal each are told apart by it; others by their shape."""
    if all(isinstance(m, type) and issubclass(m, Node) and _type_literal(m) for m in members):
        return TaggedType(members)
    return UnionType([compile_type(m) for m in members])


def _type_literal(cls: type[Node]) -> Any:
    """The class's own `type: Literal[…]` annotation, or None; evaluated alone, since the
    rest of the class may refer to the union being compiled."""
    hint = inspect.get_annotations(cls).get("type")
    if hint is None or not str(hint).startswith(("Literal[", "typing.Literal[")):
        return None
    return _evaluate(hint, cls)


# -- the walk --------------------------------------------------------------------------------

class Walk:
    """One validation of a document: reports into the sink, builds the nodes."""

    def __init__(self, doc: Document, sink: Sink, what: str) -> None:
        self.doc, self.sink, self.what = doc, sink, what  # what: the document, for messages
        self.trial: list[str] | None = None  # problems of a quiet try of a union member

    def error(self, span: Span, code: str, message: str, hint: str | None = None) -> None:
        if self.trial is not None:
            self.trial.append(message)
        else:
            self.sink.error(span, code, message, hint=hint)

    def warning(self, span: Span, code: str, message: str) -> None:
        if self.trial is None:
            self.sink.warning(span, code, message)

    def written(self, path: Path_, missing: bool = False) -> Path_:
        """The path as the document has it: without the steps a `Before` added (the index
        of a name it made a list of). missing: the last key is absent from the document."""
        out: Path_ = ()
        for i, step in enumerate(path):
            if (*out, step) in self.doc.values or (missing and i == len(path) - 1):
                out = (*out, step)
        return out

    def fail(self, path: Path_, message: str | Callable[[str], str], code: str = "E0203") -> Any:
        """Report a problem of the value at `path`; message: text, or made from the key."""
        path = self.written(path)
        if callable(message):
            message = message(_key(path))
        self.error(self.doc.value_span(path), code, message)
        return BAD

    def wrong(self, type_: Type, value: Any, path: Path_) -> Any:
        return self.fail(path, lambda key: f"'{key}' must be {type_.wanted}, got {describe(value)}")

    def attempt(self, type_: Type, value: Any, path: Path_) -> tuple[Any, list[str]]:
        """The value as `type_` and the messages of its problems, which are not reported."""
        saved, self.trial = self.trial, []
        try:
            return type_.check(value, path, self), self.trial
        finally:
            self.trial = saved

    def node(self, data: dict, cls: type[Node], path: Path_) -> Any:
        fields = cls.fields()
        given: dict[str, Any] = {}
        extra: dict[str, Any] = {}
        failed = False
        for key, value in data.items():
            name = cls.ALIASES.get(key, key)
            if name in fields:
                if name != key:
                    key_path = self.written((*path, key))
                    if name in data:
                        self.error(self.doc.span(key_path), "E0204",
                                   f"'{key}' and '{name}' in {cls.SECTION} mean the same; give one")
                        continue
                    self._rekey(key_path, (*key_path[:-1], name))
                given[name] = value
            elif cls.ENTRIES is not None and not key.startswith("$"):
                extra[key] = value
            elif cls.ANNOTATIONS and not key.startswith("$"):
                typo = next((k for k in fields if _one_edit(key, k)), None)
                if typo is not None:
                    self.warning(self.doc.span(self.written((*path, key))), "W0201",
                                 f"'{key}' in {cls.SECTION} is kept as an annotation; did you mean '{typo}'?")
                extra[key] = value
            else:
                pool = {k for k in fields if k.startswith("$")} if key.startswith("$") else set(fields)
                self.error(self.doc.span(self.written((*path, key))), "E0201",
                           f"unknown key '{key}' in {cls.SECTION}{did_you_mean(key, pool)}")
        values: dict[str, Any] = {}
        for key, f in fields.items():
            if key in given:
                got = f.type.check(given[key], (*path, key), self)
                failed |= got is BAD or got is DROP
                values[f.name] = got
            elif f.required:
                where = self.written((*path, key), missing=True)
                section = ".".join(str(x) for x in where[:-1]) or self.what
                self.error(self.doc.span(where), "E0203",
                           f"{section} has no '{key}', which is required")
                failed = True
            else:
                values[f.name] = f.fresh_default()
        if cls.ENTRIES is not None:
            entries = compile_entries(cls)
            for key, value in extra.items():
                got = entries.check(value, (*path, key), self)
                failed |= got is BAD or got is DROP
                extra[key] = got
        if failed:
            return BAD
        node = object.__new__(cls)
        node.__dict__.update(values, _doc=self.doc, _path=path, _extra=extra,
                             _given=frozenset(fields[k].name for k in given))
        problem = node.problem()
        if problem is not None:
            return self.fail(path, lambda key: f"'{key}': {problem}")
        return node

    def _rekey(self, old: Path_, new: Path_) -> None:
        """An alias's spans are filed under the declared key's path."""
        n = len(old)
        for table in (self.doc.values, self.doc.keys):
            for p in [p for p in table if p[:n] == old]:
                table[(*new, *p[n:])] = table[p]


def compile_entries(cls: type[Node]) -> Type:
    """The type of the entries of a section keyed by names."""
    plan = cls.__dict__.get("_entries")
    if plan is None:
        plan = compile_type(cls.ENTRIES)
        cls._entries = plan  # type: ignore[attr-defined]
    return plan


# -- messages --------------------------------------------------------------------------------

def describe(value: Any) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} '{value}'"


def _key(path: Path_) -> str:
    key = next((str(x) for x in reversed(path) if isinstance(x, str)), "value")
    return f"{key}[{path[-1]}]" if path and isinstance(path[-1], int) else key


def _one_edit(a: str, b: str) -> bool:
    """Whether b is a with one letter added, dropped or changed, or two neighbours swapped:
    the typos that make an annotation of an operation's key (`shap`, `reparent_too`), and
    not settings that only look alike (a sensor's `rate` is not its `frame`)."""
    if a == b or abs(len(a) - len(b)) > 1:
        return False
    i = next((i for i, (x, y) in enumerate(zip(a, b, strict=False)) if x != y), min(len(a), len(b)))
    if len(a) == len(b):
        return a[i + 1:] == b[i + 1:] or (a[i + 1:i + 2] == b[i:i + 1] and a[i:i + 1] == b[i + 1:i + 2]
                                         and a[i + 2:] == b[i + 2:])
    short, long = (a, b) if len(a) < len(b) else (b, a)
    return short[i:] == long[i + 1:]


def _one_of(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


def _items(n: int) -> str:
    return f"{n} item" if n == 1 else f"{n} items"


def validate_as(cls: type[Node], doc: Document, sink: Sink, what: str) -> Node | None:
    """Validate `doc` as a `cls`; the node, or None when it has errors (all reported)."""
    if not isinstance(doc.data, dict):
        sink.error(doc.value_span(()), "E0203", f"{what} is a mapping, not {describe(doc.data)}")
        return None
    walk = Walk(doc, sink, what)
    errors = sink.error_count
    ast = walk.node(doc.data, cls, ())
    if ast is BAD or sink.error_count > errors:
        return None
    return ast
