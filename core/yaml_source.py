"""YAML file → plain data plus the span of every key and value in it.

Values follow the YAML 1.2 core schema (only true/false are booleans, `1e-3` is a
number, `on`, `yes` and `1:30` stay strings). Duplicate keys, malformed YAML and
unsupported tags are diagnostics. Merge keys (`<<`) work.

The loader is bounded (`Limits`): file size, nesting depth, alias uses and the size of
what they expand to, scalar length and integer digits; hitting a limit, a recursive alias
or a non-printable character is a located diagnostic (E0107–E0113), never an exception.
Definitions, pipeline files, SMURF files and pipeline state files all come through here.
"""

from __future__ import annotations

import os
import re
import stat
from bisect import bisect_right
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import field
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from mpc.core.diagnostics import Sink
from mpc.core.files import special_problem
from mpc.core.record import maker, record
from mpc.core.span import Span

Path_ = tuple[str | int, ...]

class _Resolver(yaml.resolver.BaseResolver):
    """Implicit tags of the YAML 1.2 core schema."""

    def resolve(self, kind: Any, value: Any, implicit: Any) -> Any:
        """BaseResolver's tag, kept for each short scalar: it depends on the scalar's text and
        whether it was plain or quoted alone (no path resolvers here), and a definition repeats
        its values, parsed on each keystroke in `mpc lsp`."""
        if kind is not ScalarNode or len(value) > 64:
            return super().resolve(kind, value, implicit)
        key = (value, implicit)
        tag = _SCALAR_TAGS.get(key)
        if tag is None:
            if len(_SCALAR_TAGS) >= 4096:
                _SCALAR_TAGS.clear()
            tag = _SCALAR_TAGS[key] = super().resolve(kind, value, implicit)
        return tag


_SCALAR_TAGS: dict[tuple[str, Any], str] = {}  # _Resolver.resolve's, by (text, implicit)


for tag, pattern, first in [
    ("tag:yaml.org,2002:bool", r"^(?:true|True|TRUE|false|False|FALSE)$", "tTfF"),
    ("tag:yaml.org,2002:int", r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$", "-+0123456789"),
    ("tag:yaml.org,2002:float",
     r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
     r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$", "-+0123456789."),
    ("tag:yaml.org,2002:null", r"^(?:~|null|Null|NULL|)$", ["~", "n", "N", ""]),
    ("tag:yaml.org,2002:merge", r"^(?:<<)$", "<"),
]:
    _Resolver.add_implicit_resolver(tag, re.compile(pattern), list(first))


@record
class Limits:
    """How much YAML one file may hold; far above any model definition or SMURF file.

    bytes: the file; depth: nested lists and mappings; aliases: `*name` uses;
    nodes: values after expanding aliases (what an alias bomb multiplies);
    scalar: characters of one value; digits: of one integer (Python refuses > 4300).
    """

    bytes: int = 64 * 2**20
    depth: int = 200
    aliases: int = 10_000
    nodes: int = 500_000
    scalar: int = 2**20
    digits: int = 100


LIMITS = Limits()


class _Limit(Exception):
    """A limit was hit while composing; becomes a diagnostic at `mark`."""

    def __init__(self, code: str, message: str, mark: yaml.Mark | None) -> None:
        super().__init__(message)
        self.code, self.message, self.mark = code, message, mark


class _Composer(yaml.reader.Reader, yaml.scanner.Scanner, yaml.parser.Parser,
                yaml.composer.Composer, _Resolver):
    """PyYAML's composer (nodes with start and end marks) with the resolver above, and
    bounded: PyYAML composes recursively (a deep file is a RecursionError) and counts
    nothing (an alias bomb is composed as a small graph, then expanded without end)."""

    def __init__(self, stream: str, limits: Limits) -> None:
        yaml.reader.Reader.__init__(self, stream)
        yaml.scanner.Scanner.__init__(self)
        yaml.parser.Parser.__init__(self)
        yaml.composer.Composer.__init__(self)
        _Resolver.__init__(self)
        self.limits, self.depth, self.aliases = limits, 0, 0

    def compose_node(self, parent: Node | None, index: Any) -> Node:
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            self.aliases += 1
            if self.aliases > self.limits.aliases:
                raise _Limit("E0109", f"more than {self.limits.aliases} aliases", event.start_mark)
        self.depth += 1
        try:
            if self.depth > self.limits.depth:
                raise _Limit("E0110", f"lists and mappings nested more than {self.limits.depth} deep",
                             event.start_mark)
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


@record(frozen=False)
class Document:
    """A loaded YAML file: its data and where each part of it was written.

    values[path]: the span of the value at `path` (keys and list indices from the top).
    keys[path]: the span of the key that introduces the value at `path`.
    numbers[path]: the text of a value YAML read as a number (`commit: 8e99999999` is a float),
    for the hint to quote it where a string was meant.
    """

    file: str
    data: Any
    values: dict[Path_, Span] = field(default_factory=dict)
    keys: dict[Path_, Span] = field(default_factory=dict)
    numbers: dict[Path_, str] = field(default_factory=dict)

    def span(self, path: Path_) -> Span:
        """The key at `path` if it has one, else its value; else the nearest enclosing part."""
        for n in range(len(path), -1, -1):
            p = tuple(path[:n])
            if p in self.keys:
                return self.keys[p]
            if p in self.values:
                return self.values[p]
        return Span.of_file(self.file)

    def data_at(self, path: Path_) -> Any:
        """The data at `path`, or None."""
        node = self.data
        for key in path:
            try:
                node = node[key]
            except (KeyError, IndexError, TypeError):
                return None
        return node

    def value_span(self, path: Path_) -> Span:
        """The value at `path`, else the nearest enclosing part."""
        return self.values.get(tuple(path)) or self.span(path)


class _Lines:
    """Positions in `text` as editors and mpc's quoting count its lines: broken at \\n, \\r\\n and
    \\r (LSP's line breaks, and Python's reading of a text file). PyYAML, reading YAML 1.1, also
    breaks lines at U+0085, U+2028 and U+2029, so its marks' lines and columns are past any of
    those; a mark's index (its character in the text) is the same for both."""

    def __init__(self, text: str) -> None:
        self.starts = [0, *(m.end() for m in _LINE_BREAK.finditer(text))]

    def position(self, index: int) -> tuple[int, int]:
        """The 1-based line and column of character `index`."""
        line = bisect_right(self.starts, index) - 1
        return line + 1, index - self.starts[line] + 1


_LINE_BREAK = re.compile("\r\n|\r|\n")
_YAML_ONLY_BREAK = re.compile("[\x85\u2028\u2029]")  # a line break to PyYAML alone (_Lines)


def _yaml_lines(text: str) -> _Lines | None:
    """The `_Lines` of `text` when PyYAML's marks count its lines otherwise, else None."""
    return _Lines(text) if _YAML_ONLY_BREAK.search(text) else None


def _mark_position(mark: yaml.Mark | None, text: str) -> tuple[int, int]:
    """The 1-based line and column of `mark` in `text` (1, 1 without one)."""
    if mark is None:
        return 1, 1
    lines = _yaml_lines(text)
    return lines.position(mark.index) if lines else (mark.line + 1, mark.column + 1)


class _Builder:
    def __init__(self, doc: Document, sink: Sink, limits: Limits = LIMITS, text: str = "") -> None:
        self.doc, self.sink, self.limits = doc, sink, limits
        self.lines = _yaml_lines(text)
        # Span's maker (core/record.py): a span for every key and value, on each keystroke in
        # `mpc lsp` (a thousand for a TALOS definition).
        self.new_span = maker(Span)
        self.unusable = False  # a value no later step can take (a NUL character, a limit hit)
        self.nodes = 0
        self.open: set[int] = set()  # the nodes being built: an alias to one of them is a cycle

    def span(self, node: Node) -> Span:
        """Where `node` is written, made by the maker."""
        s, e = node.start_mark, node.end_mark
        if self.lines is not None:
            return self.new_span(self.doc.file, *self.lines.position(s.index), *self.lines.position(e.index))
        return self.new_span(self.doc.file, s.line + 1, s.column + 1, e.line + 1, e.column + 1)

    def scalar(self, node: ScalarNode, path: Path_) -> Any:
        v, tag = node.value, node.tag
        if len(v) > self.limits.scalar:
            self.sink.error(self.span(node), "E0111", f"a value of {len(v)} characters; "
                            f"at most {self.limits.scalar} are read")
            self.unusable = True
            return None
        if tag == "tag:yaml.org,2002:str":
            if "\0" in v:
                self.sink.error(self.span(node), "E0106", "a NUL character in a string: "
                                "no file, link, joint or other name can hold one")
                self.unusable = True
            return v
        if tag == "tag:yaml.org,2002:null":
            return None
        if tag == "tag:yaml.org,2002:bool":
            return v.lower() == "true"
        if tag == "tag:yaml.org,2002:int":
            self.doc.numbers[path] = v
            if len(v.lstrip("+-")) > self.limits.digits:
                self.sink.error(self.span(node), "E0112", f"an integer of {len(v)} "
                                f"digits; at most {self.limits.digits} are read")
                self.unusable = True
                return None
            return int(v, 0) if v[:2] in ("0o", "0x") else int(v, 10)
        if tag == "tag:yaml.org,2002:float":
            self.doc.numbers[path] = v
            low = v.lower().lstrip("+")
            return float(low.replace(".inf", "inf").replace(".nan", "nan"))
        self.sink.error(self.span(node), "E0105", f"unsupported YAML tag '{tag}'")
        return v

    def build(self, node: Node, path: Path_) -> Any:
        if self.unusable:
            return None
        self.nodes += 1
        if self.nodes > self.limits.nodes:  # aliases expand to copies: billion laughs stop here
            keyed = next((path[:n] for n in range(len(path), 0, -1) if path[:n] in self.doc.keys), None)
            where = self.doc.keys[keyed] if keyed else self.span(node)
            self.sink.error(where, "E0109", f"the aliases expand to more than {self.limits.nodes} "
                            "values")
            self.unusable = True
            return None
        self.doc.values[path] = self.span(node)
        if isinstance(node, ScalarNode):
            return self.scalar(node, path)
        if id(node) in self.open:
            self.sink.error(self.span(node), "E0108", "a recursive alias: the value "
                            "contains itself")
            self.unusable = True
            return None
        self.open.add(id(node))
        try:
            return self.collection(node, path)
        finally:
            self.open.discard(id(node))

    def collection(self, node: Node, path: Path_) -> Any:
        if isinstance(node, SequenceNode):
            return [self.build(item, (*path, i)) for i, item in enumerate(node.value)]
        assert isinstance(node, MappingNode)
        out: dict[str, Any] = {}
        merged: list[Node] = []
        for key_node, value_node in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                merged.extend(value_node.value if isinstance(value_node, SequenceNode)
                              else [value_node])
                continue
            if not isinstance(key_node, ScalarNode):
                self.sink.error(self.span(key_node), "E0105",
                                "a mapping key must be a plain value, not a list or mapping")
                continue
            key = key_node.value
            key_path = (*path, key)
            if key in out:
                self.sink.error(self.span(key_node), "E0103", f"duplicate key '{key}'",
                                notes=((self.doc.keys[key_path], "first written here"),))
                continue
            self.doc.keys[key_path] = self.span(key_node)
            out[key] = self.build(value_node, key_path)
        for source in merged:  # explicit keys win over merged ones
            if isinstance(source, MappingNode):
                for k, v in self.build(source, path).items():
                    out.setdefault(k, v)
        return out


# What `overlay` sets: texts read instead of files, and the sets collecting what was loaded.
_overlay: dict[str, str] = {}
_loaded: list[set[str]] = []


@contextmanager
def overlay(texts: Mapping[str, str]) -> Iterator[set[str]]:
    """Within it, `load` reads `texts` (by absolute path) instead of those files (an editor's
    unsaved buffers, for `mpc lsp`), and the set it gives collects the absolute path of every
    file `load` was asked for (what a check depends on). Not for threads: one at a time."""
    saved = dict(_overlay)
    _overlay.clear()
    _overlay.update(texts)
    loaded: set[str] = set()
    _loaded.append(loaded)
    try:
        yield loaded
    finally:
        _loaded.pop()
        _overlay.clear()
        _overlay.update(saved)


def load(path: Path, sink: Sink, display: str | None = None, origin: Span | None = None) -> Document | None:
    """Load a YAML file; None (with diagnostics) when it cannot be read or parsed.

    origin: where the file was named (a `defaults:` key, the command line), for the
    error when it is missing.
    """
    file = display or str(path)
    if _loaded or _overlay:
        absolute = os.path.abspath(path)
        for loaded in _loaded:
            loaded.add(absolute)
        if absolute in _overlay:
            return loads(_overlay[absolute], file, sink)
    if why := special_problem(path):  # a definition named on the command line, too
        sink.error(origin or Span.of_file(file), "E0650", f"'{file}' is not read: {why}")
        return None
    try:
        text = _read(path, LIMITS)
    except _NotAFile:
        sink.error(origin or Span.of_file(file), "E0601", f"'{file}' is not a regular file")
        return None
    except _TooLarge as e:
        sink.error(origin or Span.of_file(file), "E0113", f"'{file}' has {e.size} bytes; "
                   f"at most {LIMITS.bytes} are read")
        return None
    except FileNotFoundError:
        sink.error(origin or Span.of_file(file), "E0601", f"file '{file}' does not exist")
        return None
    except (OSError, UnicodeDecodeError) as e:
        sink.error(origin or Span.of_file(file), "E0601", f"cannot read '{file}': {e}")
        return None
    return loads(text, file, sink)


class _NotAFile(Exception):
    """A device, FIFO or socket where a YAML file was expected."""


class _TooLarge(Exception):
    def __init__(self, size: int) -> None:
        super().__init__(size)
        self.size = size


def _read(path: Path, limits: Limits) -> str:
    """The text of `path`, read no further than the limit (a FIFO or /dev/zero never ends)."""
    if not stat.S_ISREG(path.stat().st_mode):  # opening a FIFO would wait for a writer
        raise _NotAFile()
    with path.open("rb") as f:
        data = f.read(limits.bytes + 1)
        size = os.fstat(f.fileno()).st_size
    if len(data) > limits.bytes:
        raise _TooLarge(max(size, len(data)))
    return data.decode("utf-8")


_CParser: Any = getattr(getattr(yaml, "cyaml", None), "CParser", None)  # None without libyaml


class _FastComposer(*((_CParser,) if _CParser else ()), _Resolver):
    """libyaml's composer (C, about 20 times faster) with the resolver above. It counts
    nothing and composes recursively in C, so `_fast_node` lets it compose only text whose
    events (an iteration, not a recursion) stay within the limits."""

    def __init__(self, stream: str) -> None:
        _CParser.__init__(self, stream)
        _Resolver.__init__(self)


# Where libyaml and PyYAML part (found by fuzzing, tests/lsp/test_text.py): tabs, tags, `? ` keys, flow
# mappings and pairs in flow lists (PyYAML refuses some that libyaml takes, or places a key or an
# empty value one column apart), a byte order mark inside the text and line breaks other than \n
# (columns), and the end of a text without a final line break (the collections closing there).
_DIFFERENT = re.compile("[\t\r\x85\u2028\u2029\ufeff{!]|\\?(?:\\s|$)|\\[[^\\]]*:")


def _fast_node(text: str, limits: Limits) -> Node | None:
    """The node of `text` composed by libyaml, or None when it is not sure to be what _Composer
    makes: libyaml is missing, or the text is malformed or beyond a limit (then _Composer
    reports it, in its words)."""
    if not text.endswith("\n") or _DIFFERENT.search(text):
        return None
    if _CParser is None:
        return None
    if _within_limits(text, limits):
        return _compose(text)
    events = _FastComposer(text)
    try:
        depth = aliases = 0
        while events.check_event():
            event = events.get_event()
            if isinstance(event, yaml.CollectionStartEvent):
                depth += 1
                if depth + 1 > limits.depth:  # the limit counts the values inside it too
                    return None
            elif isinstance(event, yaml.CollectionEndEvent):
                depth -= 1
            elif isinstance(event, yaml.AliasEvent):
                aliases += 1
                if aliases > limits.aliases:
                    return None
    except yaml.YAMLError:
        return None
    finally:
        events.dispose()
    return _compose(text)


def _compose(text: str) -> Node | None:
    loader = _FastComposer(text)
    try:
        return loader.get_single_node()
    except yaml.YAMLError:
        return None
    finally:
        loader.dispose()


_INDENT = re.compile(r"^[ -]+", re.M)  # a line's indentation, with the dashes of `- - item`


def _within_limits(text: str, limits: Limits) -> bool:
    """Whether the text is sure to stay within the depth and alias limits, judged from its
    characters without parsing it. A block collection nested in another starts further right
    (a list under a mapping's key may share its column: two levels per column), within a
    line's indentation and dashes; a flow one opens a bracket (`{` never comes here); an alias
    is written with a `*`."""
    if text.count("*") > limits.aliases:
        return False
    indent = max((m.end() - m.start() for m in _INDENT.finditer(text)), default=0)
    return 2 * (indent + 1) + text.count("[") + 1 <= limits.depth  # + 1: the innermost value


def loads(text: str, file: str, sink: Sink, limits: Limits = LIMITS, fast: bool = False) -> Document | None:
    """Parse YAML text that came from `file`.

    fast: compose with libyaml where it is sure to give the same nodes (`mpc lsp`, which parses
    a buffer on each keystroke); the same Document and diagnostics, sooner.
    """
    if len(text) > limits.bytes:
        sink.error(Span.of_file(file), "E0113", f"'{file}' has {len(text)} characters; "
                   f"at most {limits.bytes} are read")
        return None
    node = _fast_node(text, limits) if fast else None
    if node is not None:
        return _document(node, file, sink, limits)
    loader: _Composer | None = None
    try:
        loader = _Composer(text, limits)  # the reader checks the characters already
        node = loader.get_single_node()
    except yaml.reader.ReaderError as e:
        line, col = _Lines(text).position(e.position)
        sink.error(Span(file, line, col), "E0107", f"a non-printable character (#x{e.character:04x}) "
                   "in YAML; write it escaped in a double-quoted string")
        return None
    except _Limit as e:
        line, col = _mark_position(e.mark, text)
        sink.error(Span(file, line, col), e.code, e.message)
        return None
    except yaml.MarkedYAMLError as e:
        line, col = _mark_position(e.problem_mark or e.context_mark, text)
        what = e.problem or e.context or "syntax error"
        sink.error(Span(file, line, col), "E0102", f"malformed YAML: {what}")
        return None
    except yaml.YAMLError as e:
        sink.error(Span.of_file(file), "E0102", f"malformed YAML: {e}")
        return None
    finally:
        if loader is not None:
            loader.dispose()
    if node is None:
        sink.error(Span.of_file(file), "E0104", f"'{file}' is empty")
        return None
    return _document(node, file, sink, limits, text)


def _document(node: Node, file: str, sink: Sink, limits: Limits, text: str = "") -> Document | None:
    """The Document of `node`; `text`: what PyYAML composed it from (libyaml composes no text
    with a line break of YAML's alone: `_DIFFERENT`)."""
    doc = Document(file, None)
    builder = _Builder(doc, sink, limits, text)
    doc.data = builder.build(node, ())
    return None if builder.unusable else doc
