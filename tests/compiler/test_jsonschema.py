"""The committed JSON Schema is the generated one, and it accepts the reference's examples."""

from __future__ import annotations

import json
import re
from pathlib import Path

import jsonschema
import pytest
import yaml

from mpc.compiler.jsonschema import render

ROOT = Path(__file__).resolve().parents[2]
COMMITTED = ROOT / "specs/model-definition.schema.json"
FIXTURES = sorted((ROOT / "tests/fixtures/reference").glob("*.yml"))


def test_committed_schema_is_fresh() -> None:
    assert COMMITTED.read_text() == render(), "run `mpc schema` and commit the result"
    jsonschema.Draft202012Validator.check_schema(json.loads(COMMITTED.read_text()))


@pytest.mark.parametrize("path", FIXTURES, ids=[p.stem for p in FIXTURES])
def test_schema_accepts_reference_examples(path: Path) -> None:
    jsonschema.validate(yaml.safe_load(path.read_text()), json.loads(COMMITTED.read_text()))


def test_schema_rejects_a_misspelt_key() -> None:
    doc = yaml.safe_load((ROOT / "examples/talos.yml").read_text())
    jsonschema.validate(doc, json.loads(COMMITTED.read_text()))
    doc["model"]["robtname"] = doc["model"].pop("robotname")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, json.loads(COMMITTED.read_text()))


def _properties(schema: dict) -> list[tuple[str, str, dict]]:
    """(node, key, property) of every property of the schema's nodes."""
    nodes = {"(root)": schema, **schema["$defs"]}
    return [(name, key, prop) for name, node in nodes.items()
            for key, prop in node.get("properties", {}).items()]


def test_every_property_has_a_description() -> None:
    schema = json.loads(COMMITTED.read_text())
    missing = [f"{n}.{k}" for n, k, p in _properties(schema) if len(p.get("description", "")) < 5]
    assert not missing
    assert len(_properties(schema)) > 300


def test_no_title_is_a_class_name_and_a_property_is_titled_by_its_key() -> None:
    from mpc.compiler.jsonschema import _subclasses
    from mpc.compiler.schema.base import Node

    classes = {c.__name__ for c in _subclasses(Node)}
    text = COMMITTED.read_text()
    titles = set(re.findall(r'"title": "([^"]*)"', text))
    assert not titles & classes, titles & classes
    sections = [node["title"] for node in json.loads(text)["$defs"].values()]
    assert all(t == t.lower() or " " in t for t in sections), sections
    assert not [f"{n}.{k}" for n, k, p in _properties(json.loads(text)) if p.get("title", k) != k]


def test_descriptions_carry_units_defaults_and_examples() -> None:
    defs = json.loads(COMMITTED.read_text())["$defs"]
    assert "(rad or m)" in defs["Limits"]["properties"]["min"]["description"]
    assert "Default: `input_type`." in defs["UrdfExport"]["properties"]["mesh_format"]["description"]
    assert defs["ModelSection"]["properties"]["frames"]["examples"]
    assert defs["UrdfExport"]["properties"]["mesh_format"]["enum"][-1] == "input_type"
