"""The definition language as JSON Schema (from the AST's declarations), for YAML language servers.

`mpc schema` writes it to specs/model-definition.schema.json; a test keeps the
committed file equal to what this module generates. Point an editor at it with a
first line `# yaml-language-server: $schema=<path>/model-definition.schema.json`.
"""

from __future__ import annotations

import inspect
import json
from typing import Any

from mpc.compiler.schema import Definition
from mpc.compiler.schema.base import (
    AnyType,
    BoolType,
    DictType,
    ExprType,
    IntType,
    ListType,
    LiteralType,
    Node,
    NodeType,
    OptionalType,
    StrType,
    TaggedType,
    Type,
    UnionType,
    Wrapped,
    compile_entries,
)

SCHEMA_ID = "https://mpc.invalid/model-definition.schema.json"
_EXPR = {"anyOf": [{"type": "number"}, {"type": "string"}, {"type": "array", "minItems": 2, "maxItems": 2}]}


def definition_schema() -> dict[str, Any]:
    """The JSON Schema of a model definition file."""
    defs: dict[str, Any] = {}
    schema = _node(Definition, defs)
    schema["$defs"] = dict(sorted(defs.items()))
    # `defaults` is resolved before validation (compiler/inherit.py), so the AST has no field.
    schema["properties"]["defaults"] = {
        "type": "string", "description": "a defaults file (relative to this file) whose "
        "`default_model` is merged under `model`"}
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$id"] = SCHEMA_ID
    schema["title"] = "mpc model definition"
    return schema


def render() -> str:
    """The schema as the committed file holds it: sorted keys, two-space indent."""
    return json.dumps(definition_schema(), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def _node(cls: type[Node], defs: dict[str, Any]) -> dict[str, Any]:
    """The schema of a node: its fields, and what it does with other keys."""
    properties: dict[str, Any] = {}
    required = []
    for key, f in cls.fields().items():
        prop = _type(f.type, defs)
        if not _is_ref(f.type):
            prop["title"] = key.title().replace("_", " ")
        if f.required:
            required.append(key)
        else:
            prop["default"] = f.default
        properties[key] = prop
    out: dict[str, Any] = {"type": "object", "title": cls.__name__, "properties": properties}
    if cls.__doc__ and "__doc__" in cls.__dict__:
        out["description"] = inspect.cleandoc(cls.__doc__)
    if required:
        out["required"] = required
    if cls.ENTRIES is not None:
        out["additionalProperties"] = _type(compile_entries(cls), defs)
    else:
        out["additionalProperties"] = cls.ANNOTATIONS
    for alias, target in cls.ALIASES.items():  # old spellings: same schema, marked deprecated
        if target in properties:
            properties[alias] = {**properties[target], "deprecated": True,
                                 "description": f"old spelling of '{target}'"}
        if target in required:
            required.remove(target)
            out.setdefault("allOf", []).append({"anyOf": [{"required": [target]}, {"required": [alias]}]})
    return out


def _is_ref(t: Type) -> bool:
    """Fields that are one node (or nothing) take their title from the node."""
    return isinstance(t.inner if isinstance(t, OptionalType) else t, NodeType)


def _ref(cls: type[Node], defs: dict[str, Any]) -> dict[str, Any]:
    if cls.__name__ not in defs:
        defs[cls.__name__] = {}  # taken, while its fields (which may refer to it) are described
        defs[cls.__name__] = _node(cls, defs)
    return {"$ref": f"#/$defs/{cls.__name__}"}


def _type(t: Type, defs: dict[str, Any]) -> dict[str, Any]:
    if isinstance(t, Wrapped):
        return dict(t.json) if t.json is not None else _type(t.inner, defs)
    if isinstance(t, OptionalType):
        inner = _type(t.inner, defs)
        return {"anyOf": [*inner["anyOf"], {"type": "null"}]} if list(inner) == ["anyOf"] \
            else {"anyOf": [inner, {"type": "null"}]}
    if isinstance(t, ExprType):
        return json.loads(json.dumps(_EXPR))
    if isinstance(t, StrType):
        return {"type": "string", **({"minLength": t.low} if t.low else {})}
    if isinstance(t, BoolType):
        return {"type": "boolean"}
    if isinstance(t, IntType):
        return {"type": "integer"}
    if isinstance(t, AnyType):
        return {}
    if isinstance(t, LiteralType):
        kind = "integer" if all(isinstance(v, int) for v in t.values) else "string"
        if len(t.values) == 1:
            return {"const": t.values[0], "type": kind}
        return {"enum": list(t.values), "type": kind}
    if isinstance(t, ListType):
        out = {"type": "array", "items": _type(t.item, defs)}
        return out | ({"minItems": t.low} if t.low else {}) | ({"maxItems": t.high} if t.high else {})
    if isinstance(t, DictType):
        value = _type(t.value, defs)
        out = {"type": "object", "additionalProperties": value or True}
        if isinstance(t.key, LiteralType):
            out["propertyNames"] = {"enum": list(t.key.values)}
        return out | ({"minProperties": t.low} if t.low else {})
    if isinstance(t, NodeType):
        return _ref(t.cls, defs)
    if isinstance(t, TaggedType):
        refs = {tag: _ref(cls, defs)["$ref"] for tag, cls in t.tags.items()}
        return {"oneOf": [{"$ref": r} for r in dict.fromkeys(refs.values())],
                "discriminator": {"propertyName": "type", "mapping": refs}}
    if isinstance(t, UnionType):
        return {"anyOf": [_type(m, defs) for m in t.members]}
    raise TypeError(f"no JSON Schema for {t!r}")
