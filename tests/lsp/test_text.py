"""Positions (UTF-16 columns), the YAML context at the cursor, and libyaml's fast path of the
YAML loader, which must give what the Python loader gives."""

from __future__ import annotations

import random
from pathlib import Path

from mpc.core import yaml_source
from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.lsp.text import Context, Lines, context


def test_columns_are_utf16_code_units() -> None:
    lines = Lines("a: x\nname: \"😀é\" # b: elbo\n")
    span = Span("f", 2, 12, 2, 14)  # 'b:' after an emoji (2 units) and é (1)
    assert lines.range(span)["start"]["character"] == 12
    assert lines.column(lines.range(span)["start"]) == 12
    assert lines.position(2, 9)["character"] == 9  # after 😀: one code point, two units


def test_context_of_keys_and_list_items() -> None:
    lines = Lines("model:\n  export_config:\n    - type: urdf\n      mesh_f\n  joints:\n    a: {x: 1}\n")
    assert context(lines, 3, 13).keys == ("model", "export_config", "-")
    assert context(lines, 3, 13).key is None and context(lines, 3, 13).word == "mesh_f"
    at_type = context(lines, 2, 17)
    assert (at_type.keys, at_type.key, at_type.word) == (("model", "export_config", "-"), "type", "urdf")


def test_libyaml_gives_what_the_python_loader_gives() -> None:
    """Every YAML file of the repository, and 600 mutations of them: the same data, spans and
    diagnostics (libyaml is used only where it is sure to agree, else the Python loader runs).
    Run with more mutations (and seeds) when yaml_source._DIFFERENT changes: 60 000 agreed."""
    root = Path(__file__).resolve().parents[2]
    texts = [p.read_text(encoding="utf-8") for folder in ("specs", "examples")
             for p in sorted((root / folder).rglob("*.yml"))]
    rng = random.Random(20)
    mutations = []
    pieces = [":", "- ", " ", "[", "]", "{", "}", ",", "'", "\"", "&a", "*a", "&b ", "*b", "\n  ", "\n", "#",
              "é", "!!x ", "<<: ", "? ", "|", ">", "%", "@", "`", "\\", "---\n", "...\n", "\r", "\x85",
              "\ufeff", "!", "&", "*", "~", "0x1", "1e3", "\t"]
    for _ in range(600):
        text = rng.choice(texts)
        for _ in range(rng.randrange(1, 4)):
            at = rng.randrange(len(text))
            text = text[:at] + rng.choice(pieces) + text[at + rng.randrange(3):]
        mutations.append(text)
    for text in texts + mutations:
        slow, fast = Sink(), Sink()
        a = yaml_source.loads(text, "f.yml", slow)
        b = yaml_source.loads(text, "f.yml", fast, fast=True)
        assert (a is None) == (b is None)
        if a is not None and b is not None:
            assert (a.data, a.values, a.keys) == (b.data, b.values, b.keys)
        assert slow.diagnostics == fast.diagnostics


def test_the_fast_path_keeps_the_depth_and_alias_limits() -> None:
    """Texts at both sides of the limits, nested every way YAML nests (indentation, a list
    under a key in the same column, `- - item` on one line, brackets), and aliases: the same
    diagnostics and data, whether libyaml composes them or the Python loader does."""
    limits = yaml_source.Limits(depth=10, aliases=4)
    texts = []
    for n in range(7, 13):
        texts.append("".join(f"{'  ' * i}k{i}:\n" for i in range(n)) + f"{'  ' * n}v\n")
        texts.append("".join(f"{' ' * i}k{i}:\n{' ' * i}-\n" for i in range(n // 2)) + f"{' ' * n}v\n")
        texts.append("- " * n + "v\n")
        texts.append("a: " + "[" * n + "1" + "]" * n + "\n")
        texts.append("a: &x 1\nb: [" + ", ".join(["*x"] * (n - 5)) + "]\n")
    for text in texts:
        slow, fast = Sink(), Sink()
        a = yaml_source.loads(text, "f.yml", slow, limits)
        b = yaml_source.loads(text, "f.yml", fast, limits, fast=True)
        assert slow.diagnostics == fast.diagnostics, text
        assert (a is None) == (b is None) and (a is None or (a.data, a.values) == (b.data, b.values)), text
    assert sum(1 for text in texts if not yaml_source.loads(text, "f.yml", Sink(), limits)) >= 10


def test_context_inside_flow_mappings() -> None:
    text = ("model:\n  assemble:\n    children:\n      - {model: grip, joint: {parent: ba, name: j}}\n"
            "  poses:\n    reach: {shoulder: 0.5, el}\n    rest: {a: [x, y], b: {c: ")
    lines = Lines(text)

    def at(line: int, after: str) -> Context:
        """The context just after the first `after` on the line."""
        return context(lines, line, lines.line(line).index(after) + len(after) + 1)

    assert at(3, "parent: ba") == Context(("model", "assemble", "children", "-", "joint"), "parent", "ba")
    assert at(5, "el") == Context(("model", "poses", "reach"), None, "el")
    assert at(6, "[x, ") == Context(("model", "poses", "rest"), "a", "", True)
    assert at(6, "{c: ") == Context(("model", "poses", "rest", "b"), "c", "")
    assert at(3, "}}") == Context(("model", "assemble", "children", "-"), None, "")
