"""Completion at the cursor: keys from the schema, enumerations (export, joint and sensor types,
test names), link/joint/collision/visual/material names as they are at that point of the
program, and files for `basefile`, `derived_base` and `defaults`.

What this does not do: check what is written (analysis.py).
"""

from __future__ import annotations

import os
from functools import cache
from pathlib import Path

from mpc.ir.names import Names
from mpc.lsp import schema_data
from mpc.lsp import structures as lsp
from mpc.lsp.analysis import Analysis
from mpc.lsp.text import Context, Lines, context, utf16_length

# The keys of these sections are names (else they are the schema's keys).
KEYED_BY = {"frames": "link", "links": "link", "joints": "joint", "collisions": "link",
             "visuals": "link", "materials": "material"}
# Values that name something, by their key.
VALUE_NAMES = {"parent": "link", "child": "link", "take_leaf": "link", "remove_beyond": "link",
                "link": "link", "start": "link", "stop": "link", "root": "link", "child_link": "link",
                "parent_link": "link", "joint": "joint", "joints": "joint", "material": "material",
                "mimic": "joint", "movement_depends_on": "joint", "collision": "collision",
                "visual": "visual", "links": "link", "exclude": "link", "$exclude": "link"}
_FILES = {"basefile": (".urdf", ".sdf", ".smurf", ".xml", ".mjcf", ".xacro"),
          "derived_base": (".yml", ".yaml"),
          "defaults": (".yml", ".yaml")}


def complete(analysis: Analysis, good: Analysis | None, position: lsp.Position) -> list[lsp.CompletionItem]:
    """The items at `position` of the buffer `analysis` was made from (`good`: the last analysis
    of it that got as far as its names, for a buffer being typed)."""
    lines = Lines(analysis.text)
    col = lines.column(position)
    ctx = context(lines, position["line"], col)
    start = lsp.Position(line=position["line"], character=position["character"] - utf16_length(ctx.word))
    where = lsp.Range(start=start, end=position)
    named = analysis if analysis.passed is not None or good is None else good
    indent = len(lines.line(position["line"])) - len(lines.line(position["line"]).lstrip(" -"))
    child = ctx.key == "child" and ctx.keys[-3:] == ("children", "-", "joint")  # an attach's child link
    names = named.names_at(position["line"] + 1, col, indent, child)
    items: list[lsp.CompletionItem] = []
    if ctx.key is None and ctx.keys[-1:] == ("-",):  # an item of a block list: a name or a test
        key = ctx.keys[-2] if len(ctx.keys) > 1 else ""
        if ctx.keys[-3:] == ("test", "tests", "-"):
            items += [_item(t, lsp.ItemKind.ENUM_MEMBER, where) for t in test_names()]
        if key in VALUE_NAMES and names is not None:
            items += _names(names, VALUE_NAMES[key], where, key=False)
    if ctx.key is None:
        kind = KEYED_BY.get(ctx.keys[-1]) if len(ctx.keys) == 2 and ctx.keys[0] == "model" else None
        if ctx.keys[:2] == ("model", "poses") and len(ctx.keys) == 3:
            kind = "joint"
        if kind and names is not None:
            items += _names(names, kind, where, key=True)
        items += _keys(ctx, where)
        return items
    if ctx.key in _FILES:
        return _files(analysis.path, ctx, where)
    items += [_item(v, lsp.ItemKind.ENUM_MEMBER, where)
              for v in schema_data.values_at((*ctx.keys, ctx.key))]
    if ctx.keys[-1:] == ("test",) and ctx.key == "tests":
        items += [_item(t, lsp.ItemKind.ENUM_MEMBER, where) for t in test_names()]
    kind = VALUE_NAMES.get(ctx.key)
    if kind is None and ctx.keys[:2] == ("model", "poses") and len(ctx.keys) == 3:
        kind = "joint"
    if kind and names is not None:
        items += _names(names, kind, where, key=False)
    return items


def _item(label: str, kind: int, where: lsp.Range, text: str | None = None,
          detail: str | None = None, doc: str | None = None) -> lsp.CompletionItem:
    item = lsp.CompletionItem(label=label, kind=kind, textEdit=lsp.TextEdit(
        range=where, newText=text if text is not None else label))
    if detail is not None:
        item["detail"] = detail
    if doc:
        item["documentation"] = lsp.MarkupContent(kind=lsp.MARKDOWN, value=doc)
    return item


def _keys(ctx: Context, where: lsp.Range) -> list[lsp.CompletionItem]:
    return [_item(key, lsp.ItemKind.PROPERTY, where, text=f"{key}: ",
                  doc=schema_data.description(ctx.keys, key))
            for key, prop in schema_data.keys_at(ctx.keys).items() if not prop.get("deprecated")]


def _names(names: Names, kind: str, where: lsp.Range, key: bool) -> list[lsp.CompletionItem]:
    icon = {"link": lsp.ItemKind.CLASS, "joint": lsp.ItemKind.INTERFACE,
            "material": lsp.ItemKind.COLOR}.get(kind, lsp.ItemKind.VALUE)
    return [_item(name, icon, where, text=f"{name}:" if key else name, detail=kind)
            for name in sorted(names.all(kind))]  # type: ignore[arg-type]


def _files(path: Path, ctx: Context, where: lsp.Range) -> list[lsp.CompletionItem]:
    """Files and folders under what is typed, relative to the definition's folder."""
    assert ctx.key is not None
    typed = ctx.word
    folder = (path.parent / os.path.dirname(typed)) if not typed.startswith("package://") else None
    if folder is None or not folder.is_dir():
        return []
    prefix = os.path.dirname(typed)
    out = []
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue
        text = f"{prefix}/{entry.name}" if prefix else entry.name
        if entry.is_dir():
            out.append(_item(text + "/", lsp.ItemKind.FOLDER, where))
        elif entry.name.endswith(_FILES[ctx.key]) and entry.resolve() != path.resolve():
            out.append(_item(text, lsp.ItemKind.FILE, where))
    return out


@cache
def test_names() -> tuple[str, ...]:
    """The names `test: tests:` takes: those mpc test registers (checks/registry.py)."""
    from mpc.checks import registry
    from mpc.checks.runner import run_model_tests  # noqa: F401 — registers every test

    return tuple(sorted({*registry.TESTS, *registry.DYNAMICS_CHECKS}))
