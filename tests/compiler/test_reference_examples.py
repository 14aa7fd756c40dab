"""Every example block of the language reference (model-definitions.md) parses.

The fixtures are the reference's examples with their lost indentation restored, each
inside a minimal model; they must validate with no diagnostic at all.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.compiler import inherit, schema, source
from tests.conftest import Diags

FIXTURES = sorted((Path(__file__).parents[1] / "fixtures" / "reference").glob("*.yml"))


@pytest.mark.parametrize("path", FIXTURES, ids=[p.stem for p in FIXTURES])
def test_reference_example_parses(path: Path, diags: Diags) -> None:
    doc = source.load(path, diags)
    assert doc is not None
    doc = inherit.resolve(doc, path, diags)
    assert doc is not None
    assert schema.validate(doc, diags) is not None


def test_every_section_of_the_reference_has_a_fixture() -> None:
    assert {p.stem for p in FIXTURES} == {
        "assemble", "name_editing", "cuts", "mirror", "export_config", "test", "deployment",
        "frames", "joints", "collisions", "poses", "materials", "sensors", "submechanisms",
        "submechanisms_file", "post_processing"}
