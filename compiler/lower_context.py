"""What every lowering module reads: the model, its folder, the sink; values evaluated.

Input: a validated definition (AST). Output: numbers, vectors, spans, name rules and checked
regular expressions for the modules that lower one section each (compiler/lower_*.py). It
holds no ops and no exports: each section's module returns its own, and compiler/lower.py
puts them together. It reads no file.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace
from pathlib import Path
from typing import Any

from mpc.compiler.expr import evaluate
from mpc.compiler.schema.assembly import NameEditing
from mpc.compiler.schema.base import Node
from mpc.core.diagnostics import Severity, Sink
from mpc.core.files import resolved
from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.naming import SCOPES, NameRule, bad_pattern


@record
class LowerContext:
    """The definition being lowered. `later`: how a part of the language that compiling does
    not support yet is reported (an error for `compile`, a warning for `check`)."""

    model: Any
    base_dir: Path
    sink: Sink
    resolver: PackageResolver
    later: Severity

    def quiet(self) -> LowerContext:
        """The same definition with a sink of its own (for an entry a submodel inherits: the
        model's own use of it reported already)."""
        return replace(self, sink=Sink())

    def not_yet(self, span: Span, what: str) -> None:
        message = f"{what} is not supported yet"
        if self.later is Severity.ERROR:
            self.sink.error(span, "E0202", message)
        else:
            self.sink.warning(span, "W0202", message + " (checked, but `mpc compile` will refuse it)")

    # -- values ----------------------------------------------------------------------------

    def num(self, node: Node, key: str, what: str) -> float | None:
        value = getattr(node, key)
        return None if value is None else evaluate(value, node.value_span(key), self.sink, what=what)

    def num_value(self, value: object, span: Span, what: str) -> float | None:
        return evaluate(value, span, self.sink, what=what)

    def vec(self, node: Node, key: str, what: str) -> tuple[float, ...] | None:
        values = getattr(node, key)
        if values is None:
            return None
        out = [evaluate(v, node.value_span(key, i), self.sink, what=f"{what}[{i}]")
               for i, v in enumerate(values)]
        return None if None in out else tuple(out)  # type: ignore[return-value]

    def folder_of(self, node: Node, key: str) -> Path:
        """The folder of the file that wrote `key` (a defaults file, or the definition)."""
        file = node.value_span(key).file
        return resolved(file).parent if file else self.base_dir

    # -- names -----------------------------------------------------------------------------

    def patterns(self, written: Iterable[tuple[str, Span]], where: str = "") -> list[str]:
        """The regular expressions that compile; E0305 for each other one (at its span)."""
        kept = []
        for pattern, span in written:
            problem = bad_pattern(pattern)
            if problem:
                self.sink.error(span, "E0305", f"'{pattern}'{where} is not a regular expression: {problem}")
            else:
                kept.append(pattern)
        return kept

    def replacements(self, node: Node, key: str) -> tuple[tuple[str, str], ...]:
        """A list of `{pattern: replacement}` maps, the patterns checked (E0305)."""
        items = getattr(node, key) or []
        pairs = [(pattern, str(replacement), node.value_span(key, i))
                 for i, item in enumerate(items) for pattern, replacement in item.items()]
        kept = set(self.patterns((pattern, span) for pattern, _, span in pairs))
        return tuple((pattern, replacement) for pattern, replacement, _ in pairs if pattern in kept)

    def name_rules(self, editing: NameEditing) -> tuple[NameRule, ...]:
        rules = []
        for scope in SCOPES:
            key = "" if scope == "all" else f"{scope}_"
            prefix, suffix = getattr(editing, f"{key}prefix"), getattr(editing, f"{key}suffix")
            pairs = self.replacements(editing, f"{key}replacements")
            if prefix or suffix or pairs:
                rules.append(NameRule(scope=scope, prefix=prefix or "", suffix=suffix or "",
                                      replacements=pairs))
        return tuple(rules)


def items_span(node: Node, key: str, i: int) -> Span:
    """Item `i` of `key` when it is written as a list, else the whole value (a single name)."""
    written_as_list = isinstance(node.data_at(key), list)
    return node.value_span(key, i) if written_as_list else node.value_span(key)


def pair_span(node: Node, key: str, a: str, b: str) -> Span:
    """The span of `b` in `key: {a: [..., b, ...]}` (or `{a: b}`)."""
    value = node.data_at(key, a)
    if isinstance(value, list) and b in value:
        return node.value_span(key, a, value.index(b))
    return node.value_span(key, a)


def strings(value: str | list[str] | None) -> tuple[str, ...]:
    """A `OneOrMore` value as a tuple."""
    return (value,) if isinstance(value, str) else tuple(value or ())
