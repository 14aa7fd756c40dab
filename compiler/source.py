"""YAML file → plain data plus the span of every key and value in it.

Values follow the YAML 1.2 core schema (only true/false are booleans, `1e-3` is a
number, `on`, `yes` and `1:30` stay strings). Duplicate keys, malformed YAML and
unsupported tags are diagnostics. Merge keys (`<<`) work.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from mpc.compiler.diagnostics import Sink
from mpc.ir.span import Span

Path_ = tuple[str | int, ...]

class _Resolver(yaml.resolver.BaseResolver):
    """Implicit tags of the YAML 1.2 core schema."""


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


class _Composer(yaml.reader.Reader, yaml.scanner.Scanner, yaml.parser.Parser,
                yaml.composer.Composer, _Resolver):
    """PyYAML's composer (nodes with start and end marks) with the resolver above."""

    def __init__(self, stream: str) -> None:
        yaml.reader.Reader.__init__(self, stream)
        yaml.scanner.Scanner.__init__(self)
        yaml.parser.Parser.__init__(self)
        yaml.composer.Composer.__init__(self)
        _Resolver.__init__(self)


@dataclass
class Document:
    """A loaded YAML file: its data and where each part of it was written.

    values[path]: the span of the value at `path` (keys and list indices from the top).
    keys[path]: the span of the key that introduces the value at `path`.
    """

    file: str
    data: Any
    values: dict[Path_, Span] = field(default_factory=dict)
    keys: dict[Path_, Span] = field(default_factory=dict)

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


def _span(file: str, node: Node) -> Span:
    s, e = node.start_mark, node.end_mark
    return Span(file, s.line + 1, s.column + 1, e.line + 1, e.column + 1)


class _Builder:
    def __init__(self, doc: Document, sink: Sink) -> None:
        self.doc, self.sink = doc, sink
        self.unusable = False  # a value no later step can take (a NUL character)

    def scalar(self, node: ScalarNode, path: Path_) -> Any:
        v, tag = node.value, node.tag
        if tag == "tag:yaml.org,2002:str":
            if "\0" in v:
                self.sink.error(_span(self.doc.file, node), "E0106", "a NUL character in a string: "
                                "no file, link, joint or other name can hold one")
                self.unusable = True
            return v
        if tag == "tag:yaml.org,2002:null":
            return None
        if tag == "tag:yaml.org,2002:bool":
            return v.lower() == "true"
        if tag == "tag:yaml.org,2002:int":
            return int(v, 0) if v[:2] in ("0o", "0x") else int(v, 10)
        if tag == "tag:yaml.org,2002:float":
            low = v.lower().lstrip("+")
            return float(low.replace(".inf", "inf").replace(".nan", "nan"))
        self.sink.error(_span(self.doc.file, node), "E0105", f"unsupported YAML tag '{tag}'")
        return v

    def build(self, node: Node, path: Path_) -> Any:
        self.doc.values[path] = _span(self.doc.file, node)
        if isinstance(node, ScalarNode):
            return self.scalar(node, path)
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
                self.sink.error(_span(self.doc.file, key_node), "E0105",
                                "a mapping key must be a plain value, not a list or mapping")
                continue
            key = key_node.value
            key_path = (*path, key)
            if key in out:
                self.sink.error(_span(self.doc.file, key_node), "E0103", f"duplicate key '{key}'",
                                notes=((self.doc.keys[key_path], "first written here"),))
                continue
            self.doc.keys[key_path] = _span(self.doc.file, key_node)
            out[key] = self.build(value_node, key_path)
        for source in merged:  # explicit keys win over merged ones
            if isinstance(source, MappingNode):
                for k, v in self.build(source, path).items():
                    out.setdefault(k, v)
        return out


def load(path: Path, sink: Sink, display: str | None = None, origin: Span | None = None) -> Document | None:
    """Load a YAML file; None (with diagnostics) when it cannot be read or parsed.

    origin: where the file was named (a `defaults:` key, the command line), for the
    error when it is missing.
    """
    file = display or str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        sink.error(origin or Span.of_file(file), "E0601", f"file '{file}' does not exist")
        return None
    except (OSError, UnicodeDecodeError) as e:
        sink.error(origin or Span.of_file(file), "E0601", f"cannot read '{file}': {e}")
        return None
    return loads(text, file, sink)


def loads(text: str, file: str, sink: Sink) -> Document | None:
    """Parse YAML text that came from `file`."""
    loader = _Composer(text)
    try:
        node = loader.get_single_node()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        what = e.problem or e.context or "syntax error"
        sink.error(Span(file, line, col), "E0102", f"malformed YAML: {what}")
        return None
    except yaml.YAMLError as e:
        sink.error(Span.of_file(file), "E0102", f"malformed YAML: {e}")
        return None
    finally:
        loader.dispose()
    if node is None:
        sink.error(Span.of_file(file), "E0104", f"'{file}' is empty")
        return None
    doc = Document(file, None)
    builder = _Builder(doc, sink)
    doc.data = builder.build(node, ())
    return None if builder.unusable else doc


def source_line(file: str, line: int) -> str | None:
    """Line `line` (1-based) of `file` as it is now, or None; for diagnostics and columns.

    Files are read once per (modification time, size), so an edited file is read again.
    """
    try:
        stat = os.stat(file)
        lines = _source_lines(file, (stat.st_mtime_ns, stat.st_size))
    except (OSError, UnicodeDecodeError):
        return None
    return lines[line - 1] if 0 < line <= len(lines) else None


@lru_cache(maxsize=16)
def _source_lines(file: str, stamp: tuple[int, int]) -> tuple[str, ...]:
    return tuple(Path(file).read_text(encoding="utf-8").split("\n"))
