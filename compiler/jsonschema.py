"""The definition language as JSON Schema (from the pydantic AST), for YAML language servers.

`mpc schema` writes it to specs/model-definition.schema.json; a test keeps the
committed file equal to what this module generates. Point an editor at it with a
first line `# yaml-language-server: $schema=<path>/model-definition.schema.json`.
"""

from __future__ import annotations

import json
from typing import Any

from mpc.compiler.schema import Definition
from mpc.compiler.schema.base import Node

SCHEMA_ID = "https://mpc.invalid/model-definition.schema.json"


def definition_schema() -> dict[str, Any]:
    """The JSON Schema of a model definition file."""
    schema = Definition.model_json_schema(by_alias=True, mode="validation")
    # `defaults` is resolved before validation (compiler/inherit.py), so the AST has no field.
    schema["properties"]["defaults"] = {
        "type": "string", "description": "a defaults file (relative to this file) whose "
        "`default_model` is merged under `model`"}
    _add_aliases(schema)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$id"] = SCHEMA_ID
    schema["title"] = "mpc model definition"
    return schema


def render() -> str:
    """The schema as the committed file holds it: sorted keys, two-space indent."""
    return json.dumps(definition_schema(), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def _node_classes(cls: type = Node) -> dict[str, type[Node]]:
    out = {}
    for sub in cls.__subclasses__():
        out[sub.__name__] = sub
        out.update(_node_classes(sub))
    return out


def _add_aliases(schema: dict[str, Any]) -> None:
    """Old spellings (`links` for `frames`, …) are valid too: same schema, marked deprecated."""
    classes = _node_classes()
    for name, definition in schema.get("$defs", {}).items():
        cls = classes.get(name)
        props = definition.get("properties")
        if cls is None or not props:
            continue
        for alias, target in cls.ALIASES.items():
            if target in props:
                props[alias] = {**props[target], "deprecated": True,
                                "description": f"old spelling of '{target}'"}
            if target in definition.get("required", []):
                definition["required"].remove(target)
                definition.setdefault("allOf", []).append(
                    {"anyOf": [{"required": [target]}, {"required": [alias]}]})
