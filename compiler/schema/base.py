"""Located YAML data → typed AST nodes, every problem a located diagnostic.

The language is declared as classes (`class Transform(Node): xyz: Vec3 = …`); their
annotations are read once into checks (compiler/schema/checking.py) that walk the data and
build the nodes. This module adds what the language needs on top, so that one mistake never
hides another and every problem has a file, line and column:

- Each node validates itself in a walk that knows where its mapping was written (the
  document's mappings are indexed by identity before the walk). It reports its own keys'
  problems (an unknown key with did-you-mean, an old spelling given twice, a likely typo of
  an annotation: W0201), checks its fields, and turns their problems, located by their `loc`
  below the node, into diagnostics with our messages. What a nested node reports it reports
  itself; its parent sees only that it failed.
- Leaf types raise `problem(…)`: an `Invalid` carrying the message and code.
- Lists and mappings of entries validate every entry: a bad one does not hide its
  neighbours' problems.

Three kinds of mapping appear in the language:
- closed sections (most of them): every key is declared; others are errors;
- sections keyed by names (`frames`, `joints`, …): declared `$keys`, and any other key
  is an entry named after a link, joint or collision (`__entries__` gives its type);
- annotated entries: declared keys plus free annotations that travel to SMURF
  (`ANNOTATIONS`); an annotation key close to a declared one is a warning, since it
  is most likely a typo of an operation.

Unions are told apart by the shape of the data (`Annotated[A | B, ONE_OF]`): a mapping goes
to the member that takes mappings, a list to the one that takes lists, and a union of nodes
by their `type` (`BY_TYPE`). A class's fields are read on its first use, so importing the
schema costs little: `mpc check` starts cold on every save of an editor.

The schema was declared in pydantic until 2026-11-28; building its models was a quarter of a
cold build (issue 34). The checks keep what the language took from it: its conversions of
scalars and the problems its messages are made from.
"""

import copy
import functools
import inspect
import sys
import typing
from collections.abc import Callable
from typing import Annotated, Any, ClassVar, Literal

from mpc.compiler.schema.checking import FALSE_WORDS, TRUE_WORDS, Check, Invalid, checker, invalid
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.span import Span
from mpc.core.yaml_source import Document, Path_

KEY = "\x00key\x00"  # stands for the key in a message made before the key is known


def problem(text: str, code: str = "E0203", *, at: str = "value", sub: str | None = None,
            hint: str | None = None, value: Any = None) -> Invalid:
    """An error of the value being validated. text: the message (KEY stands for its key);
    at: 'value' (its value's span) or 'key' (its key's span); sub: a key inside it to point at."""
    return invalid("mpc", value, text, text=text, code=code, at=at, sub=sub, hint=hint)


REPORTED = "mpc_reported"  # a node's problem, said by the node itself


def wrong(wanted: str, value: Any) -> Invalid:
    return problem(f"'{KEY}' must be {wanted}, got {describe(value)}")


class After:
    """Check the value further once its type is right; `fn` raises ValueError(message),
    reported as `code` (or the error's own `code` attribute)."""

    def __init__(self, fn: Callable[[Any], Any], code: str = "E0203") -> None:
        self.fn, self.code = fn, code

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        first = inner()

        def check(value: Any, walk: Any) -> Any:
            value = first(value, walk)
            try:
                self.fn(value)
            except ValueError as e:
                raise problem(f"'{KEY}': {e}", getattr(e, "code", self.code), value=value) from None
            return value
        return check


class Before:
    """Reshape the value before it is checked."""

    def __init__(self, fn: Callable[[Any], Any]) -> None:
        self.fn = fn

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        then = inner()
        return lambda value, walk: then(self.fn(value), walk)


class JsonSchema:
    """How `mpc schema` describes the type, instead of what its shape would give."""

    def __init__(self, schema: dict[str, Any]) -> None:
        self.schema = schema

    def json_schema(self, source: Any, inner: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        return copy.deepcopy(self.schema)


def _items(n: int) -> str:
    return f"{n} item" if n == 1 else f"{n} items"


class Length:
    """Bounds of a list's, a mapping's or a string's length, checked as the language does:
    too many items before the items, too few after them (a bad item is its own problem)."""

    def __init__(self, low: int | None = None, high: int | None = None) -> None:
        self.low, self.high = low, high

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        then = inner()
        if _bare(source) is list:
            return functools.partial(self._list, then)
        kind = dict if _bare(source) is dict else str
        return functools.partial(self._other, kind, then)

    def json_schema(self, source: Any, inner: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        js = inner()
        names = {list: ("minItems", "maxItems"), str: ("minLength", "maxLength"),
                 dict: ("minProperties", "maxProperties")}.get(_bare(source))
        if names:
            js.update({n: v for n, v in zip(names, (self.low, self.high), strict=True) if v})
        return js

    def _list(self, then: Check, value: Any, walk: Any) -> Any:
        if isinstance(value, list):
            if self.high is not None and len(value) > self.high:
                raise problem(f"'{KEY}' must have at most {_items(self.high)}, got {len(value)}", value=value)
            out = then(value, walk)
            if self.low and len(value) < self.low:
                if not value:
                    raise problem(f"'{KEY}' must not be empty", value=value)
                raise problem(f"'{KEY}' must have at least {_items(self.low)}, got {len(value)}", value=value)
            return out
        return then(value, walk)

    def _other(self, kind: type, then: Check, value: Any, walk: Any) -> Any:
        if isinstance(value, kind) and self.low and len(value) < self.low:
            raise problem(f"'{KEY}' must not be empty", value=value)
        return then(value, walk)


def _bare(tp: Any) -> Any:
    """The class of values a type annotation takes: `list` for `Annotated[list[str], …]`."""
    while typing.get_origin(tp) is Annotated:
        tp = typing.get_args(tp)[0]
    return typing.get_origin(tp) or tp


# -- leaf types ------------------------------------------------------------------------------

class _Expression:
    """A number as users write it: 1.5, "2*pi", ["deg", 90]; evaluated by compiler/expr.py."""

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        return self._check

    def json_schema(self, source: Any, inner: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        return {"anyOf": [{"type": "number"}, {"type": "string"},
                          {"type": "array", "minItems": 2, "maxItems": 2}]}

    @staticmethod
    def _check(value: Any, walk: Any) -> Any:
        if isinstance(value, bool | dict) or value is None:
            raise wrong("a number or an expression", value)
        return value


EXPR = _Expression()
Expr = Annotated[Any, EXPR]
Vec3 = Annotated[list[Expr], Length(3, 3)]


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


# -- unions ----------------------------------------------------------------------------------

class _Shape:
    """What a union member takes: whether a value has its shape (`fits`), is of it as it
    is (`exact`), or converts to it (`takes`); and how messages name it (`wanted`)."""

    def __init__(self, tp: Any) -> None:
        while typing.get_origin(tp) is Annotated:
            inner, *meta = typing.get_args(tp)
            if EXPR in meta:
                self.kind, self.wanted = "expr", "a number or an expression"
                return
            tp = inner
        origin = typing.get_origin(tp)
        self.values: tuple[Any, ...] = ()
        if origin is list:
            self.kind, self.wanted = "list", "a list"
        elif origin is dict or (isinstance(tp, type) and issubclass(tp, Node)):
            self.kind, self.wanted = "dict", "a mapping"
        elif origin is Literal:
            self.values = typing.get_args(tp)
            self.kind, self.wanted = "literal", f"one of {_one_of([repr(v) for v in self.values])}"
        else:
            self.kind, self.wanted = {str: ("str", "a string"), bool: ("bool", "true or false"),
                                      int: ("int", "an integer")}[tp]

    def fits(self, v: Any) -> bool:
        if self.kind in ("list", "dict"):
            return isinstance(v, list if self.kind == "list" else dict)
        return not isinstance(v, dict) if self.kind == "expr" else not isinstance(v, list | dict)

    def exact(self, v: Any) -> bool:
        return {"list": lambda: isinstance(v, list), "dict": lambda: isinstance(v, dict),
                "expr": lambda: not (isinstance(v, bool | dict) or v is None),
                "str": lambda: isinstance(v, str), "bool": lambda: isinstance(v, bool),
                "int": lambda: isinstance(v, int) and not isinstance(v, bool),
                "literal": lambda: any(v == x and type(v) is type(x) for x in self.values)}[self.kind]()

    def takes(self, v: Any) -> bool:
        if self.kind == "bool":
            return (isinstance(v, int | float) and v in (0, 1)) or (
                isinstance(v, str) and (v.lower() in TRUE_WORDS or v.lower() in FALSE_WORDS))
        if self.kind == "int":
            return isinstance(v, int) or (isinstance(v, float) and v.is_integer()) or (
                isinstance(v, str) and v.strip().lstrip("+-").isdigit())
        return self.exact(v)


class OneOf:
    """A union told apart by the data's shape, as `Annotated[A | B, ONE_OF]` (type checkers
    read the union): a list or mapping goes to the one member that takes it (whose problems
    are then the ones shown); a scalar to the first member it is exactly, else the first it
    converts to."""

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        members = typing.get_args(source)
        shapes = [_Shape(m) for m in members]
        wanted = " or ".join(dict.fromkeys(s.wanted for s in shapes))
        checks: list[Check | None] = [None] * len(members)

        def pick(v: Any) -> int | None:
            fitting = [i for i, s in enumerate(shapes) if s.fits(v)]
            if len(fitting) == 1 and isinstance(v, list | dict):
                return fitting[0]
            for test in ("exact", "takes"):
                for i in fitting:
                    if getattr(shapes[i], test)(v):
                        return i
            return None

        def check(value: Any, walk: Any) -> Any:
            i = pick(value)
            if i is None:
                raise invalid("mpc_union", value, wanted)
            member = checks[i]
            if member is None:
                member = checks[i] = checker(members[i])
            return member(value, walk)
        return check

    def json_schema(self, source: Any, inner: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        return {"oneOf": inner()["anyOf"]}


ONE_OF = OneOf()


class ByType:
    """A union of nodes told apart by their `type` literal (export entries), as
    `Annotated[A | B, BY_TYPE]`."""

    def check(self, source: Any, inner: Callable[[], Check]) -> Check:
        members: tuple[type[Node], ...] = typing.get_args(source)
        tags: dict[str, type[Node]] = {}

        def check(value: Any, walk: Any) -> Any:
            if not isinstance(value, dict):
                raise wrong("a mapping", value)
            if not tags:  # on first use: the members may contain this union
                tags.update((t, m) for m in members for t in typing.get_args(_type_literal(m)))
            kind = value.get("type")
            if not (isinstance(kind, str) and kind in tags):
                if kind is None:
                    raise problem("this entry has no 'type'; one of " + ", ".join(f"'{t}'" for t in tags)
                                  + " is required", at="value" if "type" in value else "key",
                                  sub="type" if "type" in value else None, value=value)
                word = members[0].TYPE_WORD
                raise problem(f"unknown {word} '{kind}'{did_you_mean(str(kind), set(tags))}", sub="type",
                              hint=f"{word}s: " + ", ".join(tags), value=value)
            return tags[kind].node_check()(value, walk)
        return check

    def json_schema(self, source: Any, inner: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        return {"oneOf": inner()["anyOf"]}


BY_TYPE = ByType()


def _type_literal(cls: type) -> Any:
    """The class's own `type: Literal[…]` annotation."""
    return inspect.get_annotations(cls)["type"]


# -- nodes -----------------------------------------------------------------------------------

_REQUIRED: Any = object()  # a field without a default


class _FieldSpec:
    """What `Field(…)` declares beside a field's type: its default and its key."""

    def __init__(self, default: Any, alias: str | None) -> None:
        self.default, self.alias = default, alias


def Field(default: Any = _REQUIRED, *, alias: str | None = None) -> Any:
    """A field's default and the key that gives it in the document, when not its name
    (`default: FrameDef | None = Field(None, alias="$default")`)."""
    return _FieldSpec(default, alias)


class FieldInfo:
    """A field of a node: its attribute, key, type, default and check (made on first use)."""

    def __init__(self, name: str, tp: Any, default: Any, alias: str | None, names: dict[str, Any]) -> None:
        self.name, self.annotation, self.default, self.alias = name, tp, default, alias
        self.names = names  # the module it was declared in
        self.key = alias or name
        self._check: Check | None = None

    def is_required(self) -> bool:
        return self.default is _REQUIRED

    def check(self, value: Any, walk: Any) -> Any:
        return (self._check or self.compiled())(value, walk)

    def compiled(self) -> Check:
        if self._check is None:
            self._check = checker(self.annotation, self.names)
        return self._check

    def default_value(self) -> Any:
        """The default, a fresh copy of a list or mapping for each node."""
        value = self.default
        if isinstance(value, list | dict | set):
            return copy.deepcopy(value) if value else value.copy()
        return value


class Node:
    """Base of every AST node: knows the document and path it was read from.

    SECTION: how messages name this part of the language.
    ANNOTATIONS: whether undeclared keys are kept as free annotations.
    ALIASES: old spellings still accepted, mapped to the declared key.
    ENTRIES: whether undeclared keys are entries (sections keyed by names, annotations);
    `__entries__: dict[str, EntryType]` declares their type.
    Fields are the class's annotated attributes; a value is the default.
    """

    SECTION: ClassVar[str] = ""
    ANNOTATIONS: ClassVar[bool] = False
    ALIASES: ClassVar[dict[str, str]] = {}
    TYPE_WORD: ClassVar[str] = "type"
    ENTRIES: ClassVar[bool] = False
    _fields: ClassVar[dict[str, FieldInfo]]  # each made on first use, for its own class
    _keys: ClassVar[dict[str, str]]
    _check: ClassVar[Check]
    _entry_check: ClassVar[Check]
    _doc: Document | None
    _path: Path_
    _given: frozenset[str]
    _entries: dict[str, Any]

    def problem(self) -> str | None:
        """What is wrong with the node as a whole, once its fields are right (None: nothing)."""
        return None

    def no_effect(self) -> list[tuple[str, str, str]]:
        """(code, key, message) of the keys given here that would change nothing: warned of,
        never silently ignored."""
        return []

    @classmethod
    def fields(cls) -> dict[str, FieldInfo]:
        """The fields, in the order the class and its bases declare them, by attribute name."""
        made = cls.__dict__.get("_fields")
        if made is None:
            made = {}
            for base in reversed(cls.__mro__):
                for name, tp in inspect.get_annotations(base).items():
                    if name.startswith("_") or typing.get_origin(tp) is ClassVar or tp is ClassVar:
                        continue
                    value = getattr(cls, name, _REQUIRED)
                    spec = value if isinstance(value, _FieldSpec) else _FieldSpec(value, None)
                    made.pop(name, None)
                    made[name] = FieldInfo(name, tp, spec.default, spec.alias,
                                           vars(sys.modules[base.__module__]))
            cls._fields = made
        return made

    @classmethod
    def entry_type(cls) -> Any:
        """The type of the entries (`__entries__`), Any when not declared."""
        for base in cls.__mro__:
            tp = inspect.get_annotations(base).get("__entries__")
            if tp is not None:
                return typing.get_args(tp)[1]
        return Any

    @classmethod
    def declared(cls) -> dict[str, str]:
        """Declared key in the document → attribute name."""
        plan = cls.__dict__.get("_keys")
        if plan is None:
            plan = {f.key: n for n, f in cls.fields().items()}
            cls._keys = plan
        return plan

    @classmethod
    def has_entries(cls) -> bool:
        return cls.ENTRIES and not cls.ANNOTATIONS

    @classmethod
    def node_check(cls) -> Check:
        """The check of a mapping as this node, in a walk (Walk.node)."""
        made: Check | None = cls.__dict__.get("_check")
        if made is None:
            def check(value: Any, walk: Any) -> Any:
                if not isinstance(value, dict):
                    raise wrong("a mapping", value)
                return walk.node(cls, value)
            made = cls._check = check
        return made

    @classmethod
    def build(cls, clean: dict[str, Any], walk: Any) -> "Node":
        """The node of a mapping whose keys the walk has screened; Invalid with every
        problem of its fields and entries."""
        errors: list[dict[str, Any]] = []
        values: dict[str, Any] = {}
        given = []
        for name, f in cls.fields().items():
            if f.key in clean:
                given.append(name)
                try:
                    values[name] = f.check(clean[f.key], walk)
                except Invalid as e:
                    errors += e.below(f.key)
            elif f.is_required():
                errors.append({"type": "missing", "loc": (f.key,), "input": clean, "msg": "", "ctx": {}})
            else:
                values[name] = f.default_value()
        entries: dict[str, Any] = {}
        if cls.ENTRIES:
            declared = cls.declared()
            entry = cls.__dict__.get("_entry_check")
            if entry is None:
                entry = cls._entry_check = checker(cls.entry_type())
            for key, value in clean.items():
                if key not in declared:
                    try:
                        entries[key] = entry(value, walk)
                    except Invalid as e:
                        errors += e.below(key)
        if errors:
            raise Invalid(errors)
        node = cls.__new__(cls)
        node.__dict__.update(values)
        node.__dict__.update(_given=frozenset(given), _entries=entries, _doc=None, _path=())
        return node

    def __setattr__(self, name: str, value: Any) -> None:
        if not name.startswith("_"):
            raise AttributeError(f"{type(self).__name__} is frozen: '{name}' cannot be set")
        object.__setattr__(self, name, value)

    def _place(self) -> tuple[Document, Path_]:
        """The document and path the node was read from."""
        assert self._doc is not None
        return self._doc, self._path

    @property
    def span(self) -> Span:
        """Where this node was written (the key that introduces it)."""
        doc, path = self._place()
        return doc.span(path)

    def value_span(self, *keys: str | int) -> Span:
        """Where the value at `keys` below the node was written (the node itself if absent)."""
        doc, path = self._place()
        return doc.value_span((*path, *keys))

    def key_span(self, *keys: str | int) -> Span:
        doc, path = self._place()
        return doc.span((*path, *keys))

    def data_at(self, *keys: str | int) -> Any:
        """The document's data at `keys` below the node, as written."""
        doc, path = self._place()
        return doc.data_at((*path, *keys))

    @property
    def entries(self) -> dict[str, Any]:
        """The named entries of a section keyed by names (or the free annotations)."""
        return dict(self._entries)

    @property
    def given(self) -> frozenset[str]:
        """The names of the fields the document sets (the others hold their defaults)."""
        return self._given

    def to_data(self) -> dict[str, Any]:
        """Plain data: the fields that differ from their defaults, then the entries."""
        out = {n: _plain(getattr(self, n)) for n, f in type(self).fields().items()
               if f.is_required() or getattr(self, n) != f.default}
        return out | {k: _plain(v) for k, v in self.entries.items()}

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(getattr(self, n) == getattr(other, n) for n in type(self).fields()) \
            and self.entries == other.entries

    __hash__ = None  # type: ignore[assignment]  # equal by value, and lists are not hashable

    def __repr__(self) -> str:
        items = [f"{n}={getattr(self, n)!r}" for n in type(self).fields()]
        items += [f"{k!r}: {v!r}" for k, v in self.entries.items()]
        return f"{type(self).__name__}({', '.join(items)})"


def prepare() -> None:
    """Every node's fields and checks made now, not on first use (before `mpc run` forks its
    workers, which then share them)."""
    todo: list[type[Node]] = [Node]
    while todo:
        cls = todo.pop()
        todo += cls.__subclasses__()
        for f in cls.fields().values():
            f.compiled()


def _plain(value: Any) -> Any:
    if isinstance(value, Node):
        return value.to_data()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


# -- the walk --------------------------------------------------------------------------------

_WANTED = {"string_type": "a string", "bool_type": "true or false", "bool_parsing": "true or false",
           "int_type": "an integer", "int_parsing": "an integer", "int_from_float": "an integer",
           "list_type": "a list", "dict_type": "a mapping", "model_type": "a mapping",
           "model_attributes_type": "a mapping", "string_sub_type": "a string"}


class Walk:
    """One validation of a document: what the checks carry down; reports into the sink."""

    def __init__(self, doc: Document, sink: Sink, what: str) -> None:
        self.doc, self.sink, self.what = doc, sink, what  # what: the document, for messages
        self.where: dict[int, Path_] = {}  # id of each mapping of the document → its path
        self._index(doc.data, ())

    def _index(self, value: Any, path: Path_, again: bool = False) -> None:
        if isinstance(value, dict):
            if again:
                self.where[id(value)] = path
            else:
                self.where.setdefault(id(value), path)
            for k, v in value.items():
                self._index(v, (*path, k), again)
        elif isinstance(value, list):
            for i, v in enumerate(value):
                self._index(v, (*path, i), again)

    def written(self, path: Path_, missing: bool = False) -> Path_:
        """The path as the document has it: without the steps a `Before` added (the index
        of a name it made a list of) or a union's tag. missing: the last key is absent."""
        out: Path_ = ()
        for i, step in enumerate(path):
            if (*out, step) in self.doc.values or (missing and i == len(path) - 1):
                out = (*out, step)
        return out

    def node(self, cls: type[Node], data: dict) -> Node:
        path = self.where.get(id(data), ())
        keys = cls.declared()
        clean: dict[str, Any] = {}
        failed = False
        for key, value in data.items():
            name = cls.ALIASES.get(key, key)
            if name in keys:
                if name != key:
                    key_path = self.written((*path, key))
                    if name in data:
                        self.sink.error(self.doc.span(key_path), "E0204",
                                        f"'{key}' and '{name}' in {cls.SECTION} mean the same; give one")
                        failed = True
                        continue
                    self._rekey(key_path, (*key_path[:-1], name))
                    self._index(value, (*path, name), again=True)
                clean[name] = value
            elif cls.has_entries() and not key.startswith("$"):
                clean[key] = value
            elif cls.ANNOTATIONS and not key.startswith("$"):
                typo = next((k for k in keys if _one_edit(key, k)), None)
                if typo is not None:
                    self.sink.warning(self.doc.span(self.written((*path, key))), "W0201",
                                      f"'{key}' in {cls.SECTION} is kept as an annotation; "
                                      f"did you mean '{typo}'?")
                clean[key] = value
            else:
                pool = {k for k in keys if k.startswith("$")} if key.startswith("$") else set(keys)
                self.sink.error(self.doc.span(self.written((*path, key))), "E0201",
                                f"unknown key '{key}' in {cls.SECTION}{did_you_mean(key, pool)}")
        try:
            node = cls.build(clean, self)
        except Invalid as e:
            for err in e.errors:
                self.report(err, path)
            raise invalid(REPORTED, data) from None
        if failed:
            raise invalid(REPORTED, data)
        node._doc, node._path = self.doc, path
        if (why := node.problem()) is not None:
            self.sink.error(self.doc.value_span(self.written(path)), "E0203",
                            f"'{_key(self.written(path))}': {why}")
            raise invalid(REPORTED, data)
        for code, key, message in node.no_effect():
            self.sink.warning(self.doc.span(self.written((*path, key))), code, message)
        return node

    def report(self, err: Any, base: Path_) -> None:
        """One problem of a check, `loc` below the node at `base`, as a diagnostic."""
        kind, loc = err["type"], tuple(err["loc"])
        if kind == REPORTED:
            return
        doc = self.doc
        if loc and loc[-1] == "[key]":  # a mapping's key: shown at the key
            where = self.written((*base, *loc[:-1]))
            message = self._message(err, where)
            self.sink.error(doc.span(where), "E0203", message)
            return
        if kind == "missing":
            where = self.written((*base, *loc), missing=True)
            section = ".".join(str(x) for x in where[:-1]) or self.what
            self.sink.error(doc.span(where), "E0203", f"{section} has no '{where[-1]}', which is required")
            return
        where = self.written((*base, *loc))
        ctx = err.get("ctx") or {}
        if kind == "mpc":
            at = (*where, ctx["sub"]) if ctx["sub"] else where
            span = doc.value_span(at) if ctx["at"] == "value" else doc.span(at)
            self.sink.error(span, ctx["code"], ctx["text"].replace(KEY, _key(where)), hint=ctx["hint"])
            return
        hint = None
        wants_text = kind == "string_type" or (kind == "mpc_union" and "a string" in err["msg"])
        if wants_text and (text := doc.numbers.get(where)) is not None:
            hint = f"YAML reads {text} as a number; quote it to keep it as written: '{text}'"
        self.sink.error(doc.value_span(where), "E0203", self._message(err, where), hint=hint)

    @staticmethod
    def _message(err: Any, where: Path_) -> str:
        kind, value, ctx = err["type"], err.get("input"), err.get("ctx") or {}
        key = _key(where)
        if kind == "literal_error":
            options = _literal_options(ctx["expected"])
            return (f"'{key}' must be one of {ctx['expected']}, got '{value}'"
                    + did_you_mean(str(value), options))
        if kind == "mpc_union":
            return f"'{key}' must be {err['msg']}, got {describe(value)}"
        if kind == "mpc":
            return ctx["text"].replace(KEY, key)
        wanted = _WANTED.get(kind)
        if wanted is None:  # a problem the language does not expect: mpc's bug
            raise AssertionError(f"unexpected validation error {err!r}")
        return f"'{key}' must be {wanted}, got {describe(value)}"

    def _rekey(self, old: Path_, new: Path_) -> None:
        """An alias's spans are filed under the declared key's path."""
        n = len(old)
        tables: tuple[dict[Path_, Any], ...] = (self.doc.values, self.doc.keys, self.doc.numbers)
        for table in tables:
            for p in [p for p in table if p[:n] == old]:
                table[(*new, *p[n:])] = table[p]


def _literal_options(expected: str) -> set[str]:
    """The options of "'a', 'b' or 'c'" (checking.py: _expected) as their texts."""
    import re

    return {m.group(1) if m.group(1) is not None else m.group(2)
            for m in re.finditer(r"'([^']*)'|(-?\d+)", expected)}


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


def validate_as(cls: type["Node"], doc: Document, sink: Sink, what: str) -> Node | None:
    """Validate `doc` as a `cls`; the node, or None when it has errors (all reported)."""
    if not isinstance(doc.data, dict):
        sink.error(doc.value_span(()), "E0203", f"{what} is a mapping, not {describe(doc.data)}")
        return None
    errors = sink.error_count
    try:
        ast = cls.node_check()(doc.data, Walk(doc, sink, what))
    except Invalid:
        return None
    return None if sink.error_count > errors else ast
