"""ir.Program ↔ the textual IR (`mpc compile --emit ir`): `dump` prints, `parse` reads back.

One record a line: `program …`, then `input NAME …`, `op KIND …` and `export TYPE …`,
each `field=value …` and `@ file:line:col-end_line:end_col` (its span; a hand-written line
may leave it out, and then the record's own place in the IR file is its span). The format is
generic over the dataclasses' fields (text_types walks their type hints), so a new op
or field needs no change here. It does not check what ops mean: passes do that.

Values: JSON strings (non-printable characters escaped); ints; floats as repr() (`inf`,
`-inf`, `nan`, `-0.0`); `true`/`false`/`none`; `[a, b]` for tuples, lists and sets;
`{"key": value}`; `path("…")`; `span("file", line, col, end_line, end_col)`;
`TypeName(field=value, …)` for nested dataclasses. A field equal to its default is
omitted. The span's file is written bare when it is made only of `A-Za-z0-9_./~+-`,
else as a JSON string. Known loss: a string holding two lone surrogates in a row is
escaped as a JSON pair (`\\ud83d\\ude00`) and reads back as the one character they encode.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import re
from collections.abc import Mapping, Set
from pathlib import PurePath
from typing import Any

from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken
from lark.tree import Meta

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.program import Program
from mpc.ir.text_types import (
    BAD,
    Call,
    Converter,
    FieldNode,
    ListNode,
    MapNode,
    Node,
    Registry,
    Scalar,
    field_hints,
    registry,
)

VERSION = 1
HEADER = f"# mpc ir {VERSION}"
RECORDS = ("program", "input", "op", "export")
# The Program fields that are lines of their own rather than fields of the `program` line.
_LINES = ("inputs", "ops", "exports")
_BARE_FILE = re.compile(r"[A-Za-z0-9_./~+-]+")
_BARE_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_VALUE_WORDS = {"INF", "NAN", "TRUE", "FALSE", "NONE", "NEG_INF"}  # part of "a value"
_HEADER = re.compile(r"#\s*mpc ir (\S+)\s*$")


# Printing ------------------------------------------------------------------------------

def dump(program: Program) -> str:
    """Program → IR text: header, program line, inputs, ops, exports; deterministic."""
    reg = registry()
    lines = [HEADER, _record("program", None, program, reg, skip=_LINES)]
    for key, inp in program.inputs.items():
        lines.append(_record("input", key, inp, reg, implied={"name": key}))
    for op in program.ops:
        lines.append(_record("op", type(op).kind, op, reg))
    for export in program.exports:
        lines.append(_record("export", export.type, export, reg, implied={"type": export.type}))
    return "\n".join(lines) + "\n"


def _record(word: str, key: str | None, obj: Any, reg: Registry, *, skip: tuple[str, ...] = (),
            implied: Mapping[str, Any] | None = None) -> str:
    """One record line: `word key field=value … @ span`."""
    parts = [word] if key is None else [word, key if _BARE_NAME.fullmatch(key) else _string(key)]
    implied = {k: _value(v, reg) for k, v in (implied or {}).items()}
    span = getattr(obj, "span", None)
    for name, text in _fields(obj, reg):
        if name not in skip and implied.get(name) != text and not (name == "span" and isinstance(span, Span)):
            parts.append(f"{name}={text}")
    if isinstance(span, Span):
        file = span.file if _BARE_FILE.fullmatch(span.file) else _string(span.file)
        parts.append(f"@ {file}:{span.line}:{span.col}-{span.end_line}:{span.end_col}")
    return " ".join(parts)


def _fields(obj: Any, reg: Registry) -> list[tuple[str, str]]:
    """(name, text) of a dataclass's init fields without those at their default.

    The class's own fields come first, in order, then inherited ones (an op's `part`, `spans`).
    """
    defaults = _defaults(type(obj), reg)
    shown = []
    for f in _field_order(type(obj)):
        text = _value(getattr(obj, f.name), reg)
        if defaults.get(f.name) != text:
            shown.append((f.name, text))
    return shown


@functools.cache
def _field_order(cls: type) -> tuple[dataclasses.Field[Any], ...]:
    inherited = {f.name for base in cls.__mro__[1:] if dataclasses.is_dataclass(base)
                 for f in dataclasses.fields(base)}
    return tuple(sorted((f for f in dataclasses.fields(cls) if f.init), key=lambda f: f.name in inherited))


@functools.lru_cache(maxsize=256)
def _defaults(cls: type, reg: Registry) -> dict[str, str]:
    """The printed default of each field that has one; a field printing the same is omitted."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            out[f.name] = _value(f.default, reg)
        elif f.default_factory is not dataclasses.MISSING:
            out[f.name] = _value(f.default_factory(), reg)
    return out


def _value(v: Any, reg: Registry) -> str:
    """One value → its IR text; a type the IR cannot hold is a compiler bug (TypeError)."""
    if v is None or isinstance(v, bool):
        return {None: "none", True: "true", False: "false"}[v]
    if isinstance(v, int):
        return str(int(v))
    if isinstance(v, float):
        return repr(float(v))  # the shortest text that reads back as the same float
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, PurePath):
        return f"path({_string(str(v))})"
    if isinstance(v, Span):
        return f"span({_string(v.file)}, {v.line}, {v.col}, {v.end_line}, {v.end_col})"
    if dataclasses.is_dataclass(v) and not isinstance(v, type):
        if reg.types.get(type(v).__name__) is not type(v):
            raise TypeError(f"{type(v).__qualname__} is not reachable from the IR's type hints, "
                            "so the IR parser could not read it back")
        return f"{type(v).__name__}({', '.join(f'{n}={t}' for n, t in _fields(v, reg))})"
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_value(k, reg)}: {_value(x, reg)}" for k, x in v.items()) + "}"
    if isinstance(v, tuple | list):
        return "[" + ", ".join(_value(x, reg) for x in v) + "]"
    if isinstance(v, Set):  # no order of its own: sorted by text, so the output is stable
        return "[" + ", ".join(sorted(_value(x, reg) for x in v)) + "]"
    raise TypeError(f"the IR cannot hold a value of type {type(v).__qualname__}: {v!r}")


def _string(s: str) -> str:
    """A JSON string literal; printable characters stay as they are, others are escaped."""
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ch.isprintable():
            out.append(ch)
        else:
            out.append(json.dumps(ch)[1:-1])
    return '"' + "".join(out) + '"'


# Parsing: text → records (grammar/ir.lark, IrTransformer) → Program (_Builder) -------------

@functools.cache
def parser() -> Lark:
    """The IR grammar, loaded once."""
    return Lark.open_from_package("mpc.grammar", "ir.lark", parser="lalr", propagate_positions=True)


@record(slots=True)
class Record:
    """One parsed line: `word key fields @ at`; key, at: None when absent."""

    word: str
    key: Scalar | None
    fields: tuple[FieldNode, ...]
    at: Span | None
    span: Span
    word_span: Span


@v_args(meta=True, inline=True)
class IrTransformer(Transformer[Token, Any]):
    """Parse tree of one line of ir.lark → Record and value nodes; shape only, no checks.

    file, line: where the line is, for the spans of the nodes.
    """

    def __init__(self, file: str, line: int) -> None:
        super().__init__()
        self.file, self.line = file, line

    def _span(self, meta: Meta | Token) -> Span:
        col, end = meta.column, meta.end_column
        return Span(self.file, self.line, col or 1, self.line, end or col or 1)

    def start(self, meta: Meta, record: Record | None = None) -> Record | None:
        return record

    def record(self, meta: Meta, word: Token, key: Scalar | None, *rest: Any) -> Record:
        return Record(str(word), key, rest[:-1], rest[-1], self._span(meta), self._span(word))

    def field(self, meta: Meta, name: Token, value: Node) -> FieldNode:
        return FieldNode(str(name), value, self._span(name))

    def at(self, meta: Meta, file: Token, *numbers: Token) -> Span:
        name = json.loads(file) if file.type == "STRING" else str(file)
        return Span(name, *(int(n) for n in numbers))

    def name(self, meta: Meta, tok: Token) -> Scalar:
        return Scalar(str(tok), self._span(meta))

    def string(self, meta: Meta, tok: Token) -> Scalar:
        return Scalar(json.loads(tok), self._span(meta))

    def number(self, meta: Meta, tok: Token) -> Scalar:
        is_int = tok.lstrip("-").isdigit()
        return Scalar(int(tok) if is_int else float(tok), self._span(meta))

    def inf(self, meta: Meta) -> Scalar:
        return Scalar(math.inf, self._span(meta))

    def neg_inf(self, meta: Meta, tok: Token) -> Scalar:
        return Scalar(-math.inf, self._span(meta))

    def nan(self, meta: Meta) -> Scalar:
        return Scalar(math.nan, self._span(meta))

    def true(self, meta: Meta) -> Scalar:
        return Scalar(True, self._span(meta))

    def false(self, meta: Meta) -> Scalar:
        return Scalar(False, self._span(meta))

    def none(self, meta: Meta) -> Scalar:
        return Scalar(None, self._span(meta))

    def list(self, meta: Meta, *items: Node) -> ListNode:
        return ListNode(items, self._span(meta))

    def mapping(self, meta: Meta, *pairs: tuple[Node, Node]) -> MapNode:
        return MapNode(pairs, self._span(meta))

    def pair(self, meta: Meta, key: Node, value: Node) -> tuple[Node, Node]:
        return key, value

    def call(self, meta: Meta, name: Token, *args: Node | FieldNode) -> Call:
        positional = tuple(a for a in args if not isinstance(a, FieldNode))
        named = tuple(a for a in args if isinstance(a, FieldNode))
        return Call(str(name), positional, named, self._span(meta), self._span(name))


def parse(text: str, file: str, sink: Sink) -> Program | None:
    """Parse IR text (from `file`, for diagnostics); None after reporting errors.

    Codes: E0230 syntax, E0231 unknown record type, op kind, type or field, E0232 a value of
    the wrong type, E0233 a missing required field, E0234 a duplicate or a value whose class
    refuses it. Each line is parsed on its own, so every line's errors are reported.
    """
    before = sink.error_count
    records = []
    for number, line in enumerate(text.split("\n"), 1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            _check_header(stripped, Span(file, number, 1, number, len(line) + 1), sink)
            continue
        try:
            record = IrTransformer(file, number).transform(parser().parse(line))
        except UnexpectedInput as e:
            _syntax_error(e, line, Span(file, number, 1), sink)
            continue
        except RecursionError:  # the transformer recurses once per nesting level
            sink.error(Span(file, number, 1), "E0230", "invalid IR: values nested too deeply")
            continue
        if record is not None:
            records.append(record)
    program = _Builder(registry(), sink, file).program(records, sink.error_count > before)
    return None if sink.error_count > before else program


def _check_header(comment: str, span: Span, sink: Sink) -> None:
    match = _HEADER.match(comment)
    if match and match.group(1) != str(VERSION):
        sink.error(span, "E0230", f"invalid IR: version {match.group(1)} is not supported "
                                  f"(this mpc reads version {VERSION})")


def _syntax_error(e: UnexpectedInput, line: str, at: Span, sink: Sink) -> None:
    """A lark error → E0230 at its column: `invalid IR: unexpected …`."""
    col = e.column if isinstance(e.column, int) and e.column > 0 else len(line.rstrip()) + 1
    if isinstance(e, UnexpectedCharacters):
        found = f"'{line[e.pos_in_stream]}'"
    elif isinstance(e, UnexpectedToken) and e.token.type != "$END":
        found = f"'{e.token}'"
    else:
        found, col = "end of line", len(line.rstrip()) + 1
    names = set(getattr(e, "expected", None) or getattr(e, "allowed", None) or ())
    if "NUMBER" in names:  # where a value may start, list the kinds of value rather than tokens
        names = (names - {"NUMBER", "STRING", "NAME", "LSQB", "LBRACE"}) | {"a value"}
    expected = sorted(_terminal(t) for t in names if t not in _VALUE_WORDS)
    hint = f"expected {' or '.join(expected)}" if expected else None
    sink.error(Span(at.file, at.line, col, at.line, col + 1), "E0230", f"invalid IR: unexpected {found}",
               hint=hint)


def _terminal(name: str) -> str:
    """A terminal's name, for a hint: `'='` for a literal, `a name` for NAME."""
    words = {"NAME": "a name", "STRING": "a string", "INT": "an integer", "FILE": "a file name",
             "$END": "end of line", "<END-OF-FILE>": "end of line"}
    if name in words:
        return words[name]
    try:
        return f"'{parser().get_terminal(name).pattern.value}'"
    except KeyError:
        return name


@record(frozen=False)
class _Builder:
    """Records → Program: classes from the registry, fields checked by their type hints."""

    reg: Registry
    sink: Sink
    file: str

    def program(self, records: list[Record], broken: bool) -> Program | None:
        """All records → the Program, or None after reporting every error.

        broken: a line had a syntax error (it may have been the program line).
        """
        conv = Converter(self.reg)
        head: Record | None = None
        inputs: dict[str, Any] = {}
        first: dict[str, Span] = {}
        ops, exports = [], []
        for rec in records:
            key = rec.key.value if rec.key is not None else None
            key_span = rec.key.span if rec.key is not None else rec.span
            if rec.word not in RECORDS:
                conv.error(rec.word_span, "E0231", f"unknown record type '{rec.word}'"
                           f"{did_you_mean(rec.word, set(RECORDS))}")
            elif rec.word == "program":
                if rec.key is not None:
                    conv.error(key_span, "E0230", "invalid IR: 'program' takes no name")
                elif head is not None:
                    conv.error(rec.word_span, "E0234", f"a second 'program' line (the first is at "
                                                       f"line {head.span.line})")
                else:
                    head = rec
            elif not isinstance(key, str):
                what = {"input": "its name", "op": "its kind", "export": "its type"}[rec.word]
                conv.error(rec.span, "E0233", f"'{rec.word}' line is missing {what}")
            elif rec.word == "input":
                value = self.record(conv, rec, self.reg.input, f"input '{key}'", {"name": key})
                if key in inputs:
                    conv.error(key_span, "E0234",
                               f"input '{key}' is defined twice (first at line {first[key].line})")
                elif value is not BAD:
                    inputs[key], first[key] = value, rec.span
            elif rec.word == "op":
                if key not in self.reg.ops:
                    conv.error(key_span, "E0231",
                               f"unknown op kind '{key}'{did_you_mean(key, set(self.reg.ops))}")
                else:
                    ops.append(self.record(conv, rec, self.reg.ops[key], f"op '{key}'", {}))
            elif key not in self.reg.exports:
                conv.error(key_span, "E0231",
                           f"unknown export type '{key}'{did_you_mean(key, set(self.reg.exports))}")
            else:
                exports.append(self.record(conv, rec, self.reg.exports[key], f"export '{key}'",
                                           {"type": key}))
        program = None
        if head is None and not broken:  # a program line with a syntax error was reported already
            conv.error(Span(self.file, 1, 1), "E0233", "the IR has no 'program' line")
        elif head is not None:
            for f in head.fields:
                if f.name in _LINES:
                    conv.error(f.name_span, "E0231", f"program has no field '{f.name}': "
                                                     f"{f.name} are lines of their own")
            head = dataclasses.replace(head, fields=tuple(f for f in head.fields if f.name not in _LINES))
            given = {"inputs": inputs, "ops": tuple(ops), "exports": tuple(exports)}
            program = self.record(conv, head, self.reg.program, "program", given)
        for span, code, message in sorted(conv.errors, key=lambda e: (e[0].line, e[0].col)):
            self.sink.error(span, code, message)
        return None if conv.errors else program

    def record(self, conv: Converter, rec: Record, cls: type, owner: str, given: dict[str, Any]) -> Any:
        """One record → an instance of `cls`; `given`: values the record's syntax supplies."""
        hints = field_hints(cls)
        given = {k: v for k, v in given.items() if k in hints}
        if rec.at is not None:
            if "span" not in hints or any(f.name == "span" for f in rec.fields):
                why = "has no span" if "span" not in hints else "has both '@ …' and a field 'span'"
                return conv.error(rec.span, "E0231" if "span" not in hints else "E0234", f"{owner} {why}")
            given["span"] = rec.at
        elif "span" in hints and not any(f.name == "span" for f in rec.fields):
            given["span"] = rec.span  # hand-written: the line stands in for what it came from
        kwargs = conv.fields(cls, rec.fields, owner, rec.span, given)
        return BAD if kwargs is None else conv.build(cls, kwargs, owner, rec.span)
