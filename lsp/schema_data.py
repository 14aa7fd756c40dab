"""`mpc schema`'s JSON Schema (compiler/jsonschema.py), read as data: the keys allowed under a
path of keys, the values an enumeration allows, and what a key means.

A key's meaning is the schema's `description` where it has one, else the row of a key
table in specs/ that names it (`| \\`key\\` | … |`). What this does not do: validate (the
compiler's schema does).
"""

from __future__ import annotations

import re
from functools import cache
from pathlib import Path
from typing import Any

from mpc.compiler.jsonschema import definition_schema


@cache
def schema() -> dict[str, Any]:
    return definition_schema()


def _resolve(node: dict[str, Any]) -> list[dict[str, Any]]:
    """The alternatives a schema node stands for, with `$ref`s followed."""
    out: list[dict[str, Any]] = []
    stack = [node]
    while stack:
        n = stack.pop(0)
        if not isinstance(n, dict):
            continue
        if "$ref" in n:
            stack.append(schema()["$defs"][n["$ref"].rsplit("/", 1)[-1]])
            continue
        alternatives = n.get("anyOf") or n.get("oneOf") or n.get("allOf")
        if alternatives and "properties" not in n:
            stack.extend(alternatives)
            continue
        out.append(n)
    return out


def at(keys: tuple[str, ...]) -> list[dict[str, Any]]:
    """The schema nodes of the value under `keys` ("-": a list's item), all alternatives."""
    nodes = _resolve(schema())
    for key in keys:
        nxt: list[dict[str, Any]] = []
        for n in nodes:
            if key == "-":
                if "items" in n:
                    nxt.extend(_resolve(n["items"]))
            elif key in n.get("properties", {}):
                nxt.extend(_resolve(n["properties"][key]))
            elif isinstance(n.get("additionalProperties"), dict):
                nxt.extend(_resolve(n["additionalProperties"]))
        nodes = nxt
    return nodes


def keys_at(keys: tuple[str, ...]) -> dict[str, dict[str, Any]]:
    """The keys a mapping under `keys` may have, with their schema."""
    out: dict[str, dict[str, Any]] = {}
    for n in at(keys):
        for key, prop in n.get("properties", {}).items():
            out.setdefault(key, prop)
    return out


def values_at(keys: tuple[str, ...]) -> list[str]:
    """The values an enumeration under `keys` allows."""
    out: list[str] = []
    for n in at(keys):
        for value in [*n.get("enum", []), *([n["const"]] if "const" in n else [])]:
            if isinstance(value, str) and value not in out:
                out.append(value)
    if keys[-1:] == ("type",) and keys[-2:-1] == ("-",):  # a tagged list entry's tags
        out.extend(tag for tag in tags_under(keys[:-1]) if tag not in out)
    return out


def tags_under(keys: tuple[str, ...]) -> list[str]:
    """The `type`s the entries of a list may have (keys ending in "-"; export_config: urdf, sdf, …)."""
    out: list[str] = []
    for n in at(keys[:-1]) if keys[-1:] == ("-",) else ():
        item = n.get("items")
        mapping = ((item.get("discriminator") or {}).get("mapping") or {}) if isinstance(item, dict) else {}
        out.extend(tag for tag in mapping if tag not in out)
    return out


def description(keys: tuple[str, ...], key: str) -> str | None:
    """What `key` under `keys` means: the schema's words, else a specs/ table row."""
    prop = keys_at(keys).get(key)
    words = []
    for n in [prop, *(_resolve(prop) if prop else [])]:
        if n and n.get("description") and n["description"] not in words:
            words.append(n["description"])
    if prop:
        unit = prop.get("unit") or prop.get("x-unit")
        if unit:
            words.append(f"unit: {unit}")
        if "default" in prop and prop["default"] not in (None, [], {}):
            words.append(f"default: `{prop['default']}`")
    if words:
        return "\n\n".join(words)
    return specs_row(key, keys)


_SPECS = Path(__file__).resolve().parent.parent / "specs"


@cache
def _spec_rows() -> dict[str, list[tuple[str, str]]]:
    """Every key named in the first cell of a specs/ table: (file, the row's other cells)."""
    rows: dict[str, list[tuple[str, str]]] = {}
    if not _SPECS.is_dir():
        return rows
    for md in sorted(_SPECS.glob("*.md")):
        for line in md.read_text(encoding="utf-8").splitlines():
            if not line.startswith("| `"):
                continue
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            for key in re.findall(r"`([^`]+)`", cells[0]):
                rows.setdefault(key, []).append((md.name, " | ".join(c for c in cells[1:] if c)))
    return rows


def specs_row(key: str, keys: tuple[str, ...] = ()) -> str | None:
    """The specs/ row of `key`, preferring the file named after a section above it."""
    found = _spec_rows().get(key)
    if not found:
        return None
    for section in reversed(keys):
        for file, text in found:
            if file.startswith(section.rstrip("s")):
                return f"{text}\n\n(specs/{file})"
    file, text = found[0]
    return f"{text}\n\n(specs/{file})"
