"""Located YAML data → typed AST nodes (pydantic), every problem a located diagnostic.

Two steps. `screen` walks the data beside the schema and removes, with a diagnostic
each, keys that are not in the language (with a *did you mean*), so that nothing is
silently ignored and one mistake does not hide the others. Then pydantic validates
the types, and its errors are mapped back onto spans. Finally every node learns the
document and path it came from, so later stages can point at the user's text.

Three kinds of mapping appear in the language:
- closed sections (most of them): every key is declared; others are errors;
- sections keyed by names (`frames`, `joints`, …): declared `$keys`, and any other key
  is an entry named after a link, joint or collision (`ENTRIES`);
- annotated entries: declared keys plus free annotations that travel to SMURF
  (`ANNOTATIONS`); an annotation key close to a declared one is a warning, since it
  is most likely a typo of an operation.
"""

from __future__ import annotations

import types
import typing
from typing import Annotated, Any, ClassVar, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    WithJsonSchema,
)
from pydantic_core import PydanticCustomError

from mpc.compiler.diagnostics import Sink, did_you_mean
from mpc.compiler.source import Document, Path_
from mpc.ir.span import Span


class Marker:
    """Metadata on an Annotated type that later passes look for (expressions, names)."""

    def __init__(self, kind: str) -> None:
        self.kind = kind

    def __repr__(self) -> str:
        return f"Marker({self.kind!r})"


EXPR = Marker("expr")


def _expr_shape(value: Any) -> Any:
    if isinstance(value, bool) or value is None or isinstance(value, dict):
        raise PydanticCustomError("expr_type", "must be a number or an expression")
    return value


# A number as users write it: 1.5, "2*pi", ["deg", 90]; evaluated by compiler/expr.py.
Expr = Annotated[
    Any, AfterValidator(_expr_shape), EXPR,
    WithJsonSchema({"anyOf": [{"type": "number"}, {"type": "string"},
                              {"type": "array", "minItems": 2, "maxItems": 2}]}),
]
Vec3 = Annotated[list[Expr], Field(min_length=3, max_length=3)]
StrList = Annotated[list[str], Field(min_length=1)]


def str_or_list(value: Any) -> Any:
    """Many keys take one name or a list of names; the AST always holds a list."""
    return [value] if isinstance(value, str) else value


OneOrMore = Annotated[list[str], BeforeValidator(str_or_list),
                      WithJsonSchema({"anyOf": [{"type": "string"},
                                                {"type": "array", "items": {"type": "string"}}]})]


class Node(BaseModel):
    """Base of every AST node: knows the document and path it was read from.

    SECTION: how messages name this part of the language.
    ENTRIES: for sections keyed by names, the node type of each entry.
    ANNOTATIONS: whether undeclared keys are kept as free annotations.
    ALIASES: old spellings still accepted, mapped to the declared key.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)
    SECTION: ClassVar[str] = ""
    ENTRIES: ClassVar[type | None] = None
    ANNOTATIONS: ClassVar[bool] = False
    ALIASES: ClassVar[dict[str, str]] = {}
    TYPE_WORD: ClassVar[str] = "type"
    _doc: Document | None = PrivateAttr(default=None)
    _path: Path_ = PrivateAttr(default=())

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
        return dict(self.model_extra or {})

    @classmethod
    def keys(cls) -> set[str]:
        return {f.alias or name for name, f in cls.model_fields.items()}

    @classmethod
    def field_for(cls, key: str) -> Any:
        for name, f in cls.model_fields.items():
            if (f.alias or name) == key:
                return f
        return None


class OpenNode(Node):
    """A node that keeps undeclared keys (entries or annotations)."""

    model_config = ConfigDict(extra="allow", frozen=True, populate_by_name=True)


# -- screening ------------------------------------------------------------------------------

_DROP = object()


def _union_members(tp: Any) -> list[Any]:
    return [a for a in typing.get_args(tp) if a is not type(None)]


def _tagged(members: list[Any]) -> dict[str, type[Node]] | None:
    """For a union of nodes told apart by a `type` literal: tag → node class."""
    if len(members) < 2:
        return None
    table: dict[str, type[Node]] = {}
    for m in members:
        if not (isinstance(m, type) and issubclass(m, Node)):
            return None
        f = m.model_fields.get("type")
        if f is None or typing.get_origin(f.annotation) is not Literal:
            return None
        for tag in typing.get_args(f.annotation):
            table[tag] = m
    return table


class Screen:
    """Walks data beside a schema type; see the module docstring."""

    def __init__(self, doc: Document, sink: Sink) -> None:
        self.doc, self.sink = doc, sink
        self.shortened: set[Path_] = set()  # lists that lost items here (their errors are reported)

    def __call__(self, data: Any, tp: Any, path: Path_) -> Any:
        origin = typing.get_origin(tp)
        if origin is Annotated:
            return self(data, typing.get_args(tp)[0], path)
        if origin in (typing.Union, types.UnionType):
            members = _union_members(tp)
            tags = _tagged(members)
            if tags is not None and isinstance(data, dict):
                return self.tagged(data, tags, path)
            for m in members:  # the first member whose shape fits the data
                bare = typing.get_args(m)[0] if typing.get_origin(m) is Annotated else m
                shape = typing.get_origin(bare) or bare
                is_node = isinstance(shape, type) and issubclass(shape, Node)
                if (isinstance(data, dict) and (shape is dict or is_node)) or \
                        (isinstance(data, list) and shape is list):
                    return self(data, m, path)
                if isinstance(data, dict) and shape is list:  # one item where a list may stand
                    (item,) = typing.get_args(bare)
                    if isinstance(item, type) and issubclass(item, Node):
                        return self(data, item, path)
            return data
        if origin is list and isinstance(data, list):
            (item,) = typing.get_args(tp) or (Any,)
            out = [self(x, item, (*path, i)) for i, x in enumerate(data)]
            if _DROP in out:
                self.shortened.add(path)
            return [x for x in out if x is not _DROP]
        if origin is dict and isinstance(data, dict):
            value_tp = typing.get_args(tp)[1] if typing.get_args(tp) else Any
            return {k: self(v, value_tp, (*path, k)) for k, v in data.items()}
        if isinstance(tp, type) and issubclass(tp, Node) and isinstance(data, dict):
            return self.node(data, tp, path)
        return data

    def tagged(self, data: dict, tags: dict[str, type[Node]], path: Path_) -> Any:
        kind = data.get("type")
        if isinstance(kind, str) and kind in tags:
            return self.node(data, tags[kind], path)
        span = self.doc.value_span((*path, "type")) if "type" in data else self.doc.span(path)
        if kind is None:
            self.sink.error(span, "E0203", "this entry has no 'type'; one of "
                            + ", ".join(f"'{t}'" for t in tags) + " is required")
        else:
            word = next(iter(tags.values())).TYPE_WORD
            self.sink.error(span, "E0203", f"unknown {word} '{kind}'{did_you_mean(str(kind), set(tags))}",
                            hint=f"{word}s: " + ", ".join(tags))
        return _DROP

    def node(self, data: dict, tp: type[Node], path: Path_) -> dict:
        known = tp.keys()
        out: dict[str, Any] = {}
        for key, value in data.items():
            key_path = (*path, key)
            name = tp.ALIASES.get(key, key)
            if name in known:
                if name != key and name in data:
                    self.sink.error(self.doc.span(key_path), "E0204",
                                    f"'{key}' and '{name}' in {tp.SECTION} mean the same; give one")
                    continue
                f = tp.field_for(name)
                out[name] = self(value, f.annotation if not f.metadata else
                                 Annotated[f.annotation, *f.metadata], key_path)
                if name != key:
                    self._rekey(key_path, (*path, name))
            elif tp.ENTRIES is not None and not key.startswith("$"):
                out[key] = self(value, tp.ENTRIES, key_path)
            elif tp.ANNOTATIONS and not key.startswith("$"):
                near = did_you_mean(key, known)
                if near:
                    self.sink.warning(self.doc.span(key_path), "W0201",
                                      f"'{key}' in {tp.SECTION} is kept as an annotation{near}")
                out[key] = value
            else:
                pool = {k for k in known if k.startswith("$")} if key.startswith("$") else known
                self.sink.error(self.doc.span(key_path), "E0201",
                                f"unknown key '{key}' in {tp.SECTION}{did_you_mean(key, pool)}")
        return out

    def _rekey(self, old: Path_, new: Path_) -> None:
        """An alias's spans are filed under the declared key's path."""
        n = len(old)
        for table in (self.doc.values, self.doc.keys):
            for p in [p for p in table if p[:n] == old]:
                table[(*new, *p[n:])] = table[p]


# -- pydantic errors → diagnostics -----------------------------------------------------------

_WANTED = {"string_type": "a string", "dict_type": "a mapping", "list_type": "a list",
           "model_type": "a mapping", "model_attributes_type": "a mapping",
           "float_type": "a number", "int_type": "an integer", "bool_type": "true or false",
           "float_parsing": "a number", "int_parsing": "an integer", "bool_parsing": "true or false",
           "int_from_float": "an integer", "expr_type": "a number or an expression"}


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


def _clean_loc(loc: tuple, data: Any, missing: bool) -> tuple:
    """pydantic's loc without the union-member and validator tags it inserts."""
    out: list[Any] = []
    for i, x in enumerate(loc):
        in_list = isinstance(data, list) and isinstance(x, int) and 0 <= x < len(data)
        if (isinstance(data, dict) and x in data) or in_list:
            data = data[x]
        elif missing and i == len(loc) - 1 and isinstance(x, str):
            pass
        else:
            continue
        out.append(x)
    return tuple(out)


def _key(loc: tuple) -> str:
    key = next((str(x) for x in reversed(loc) if isinstance(x, str)), "value")
    return f"{key}[{loc[-1]}]" if loc and isinstance(loc[-1], int) else key


def _message(err: dict[str, Any], loc: tuple, sections: str) -> str:
    key = _key(loc)
    kind, value = err["type"], err.get("input")
    if kind == "missing":
        section = ".".join(str(x) for x in loc[:-1]) or sections
        return f"{section} has no '{key}', which is required"
    if kind == "literal_error":
        expected = err.get("ctx", {}).get("expected", "")
        options = {o.strip(" '") for o in expected.replace(" or ", ",").split(",")}
        return f"'{key}' must be one of {expected}, got '{value}'" + did_you_mean(str(value), options)
    if kind in _WANTED:
        return f"'{key}' must be {_WANTED[kind]}, got {describe(value)}"
    if kind in ("too_short", "string_too_short") and isinstance(value, list | str | dict) and not value:
        return f"'{key}' must not be empty"
    if kind in ("too_short", "too_long") and isinstance(value, list):
        want = err["msg"].split("have ", 1)[-1].split(" after")[0]
        return f"'{key}' must have {want}, got {len(value)}"
    if kind == "value_error":
        return f"'{key}': {err.get('ctx', {}).get('error', err['msg'])}"
    return f"'{key}': {err['msg']}"


def _union_message(errs: list[dict[str, Any]], loc: tuple) -> str:
    wanted = []
    for e in errs:
        w = _WANTED.get(e["type"], "a mapping" if e["type"] == "missing" else None)
        if w and w not in wanted:
            wanted.append(w)
    value = errs[0].get("input")
    return f"'{_key(loc)}' must be {' or '.join(wanted) or 'of another form'}, got {describe(value)}"


def report(e: ValidationError, doc: Document, data: Any, sink: Sink, what: str,
           shortened: set[Path_] = frozenset()) -> None:  # type: ignore[assignment]
    """Map pydantic's errors onto spans; errors of one union value become one diagnostic.

    shortened: lists from which screening removed items; "too short" there only repeats it.
    """
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for err in e.errors():
        loc = _clean_loc(tuple(err["loc"]), data, err["type"] == "missing")
        if err["type"] == "too_short" and loc in shortened:
            continue
        groups.setdefault(loc, []).append(err)
    for loc, errs in groups.items():
        missing = [x for x in errs if x["type"] == "missing" and len(errs) == 1]
        span = doc.span(loc) if missing else doc.value_span(loc)
        message = _message(errs[0], loc, what) if len(errs) == 1 else _union_message(errs, loc)
        sink.error(span, "E0203", message)


def attach(node: Any, path: Path_, doc: Document) -> None:
    """Tell every node in the tree its document and path."""
    if isinstance(node, Node):
        node._doc, node._path = doc, path
        for name, f in type(node).model_fields.items():
            attach(getattr(node, name), (*path, f.alias or name), doc)
        for key, value in (node.model_extra or {}).items():
            attach(value, (*path, key), doc)
    elif isinstance(node, list):
        for i, item in enumerate(node):
            attach(item, (*path, i), doc)
    elif isinstance(node, dict):
        for k, v in node.items():
            attach(v, (*path, k), doc)


def validate_as(cls: type[Node], doc: Document, sink: Sink, what: str) -> Node | None:
    """Screen, validate and locate `doc` as a `cls`; None when it has errors."""
    if not isinstance(doc.data, dict):
        sink.error(doc.value_span(()), "E0203", f"{what} is a mapping, not {describe(doc.data)}")
        return None
    errors = sink.error_count
    screen = Screen(doc, sink)
    data = screen(doc.data, cls, ())
    try:
        ast = cls.model_validate(data)
    except ValidationError as e:
        report(e, doc, data, sink, what, screen.shortened)
        return None
    if sink.error_count > errors:
        return None
    attach(ast, (), doc)
    return ast
