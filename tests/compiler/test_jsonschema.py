"""The committed JSON Schema is the generated one, and it accepts the reference's examples."""

from __future__ import annotations

import json
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


@pytest.mark.parametrize("path", FIXTURES, ids=[p.stem for p in FIXTURES])
def test_schema_accepts_reference_examples(path: Path) -> None:
    jsonschema.validate(yaml.safe_load(path.read_text()), json.loads(COMMITTED.read_text()))


def test_schema_rejects_a_misspelt_key() -> None:
    doc = yaml.safe_load((ROOT / "examples/talos.yml").read_text())
    jsonschema.validate(doc, json.loads(COMMITTED.read_text()))
    doc["model"]["robtname"] = doc["model"].pop("robotname")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, json.loads(COMMITTED.read_text()))
