"""The schema on pydantic is the language the validator before it accepted, with the same diagnostics.

tests/schema_corpus.py draws the corpus (every definition of the repository and 16 seeded
mutations of each); its fixture holds what mpc's own validator (compiler/schema/ before
pydantic) reported for each document: code, span, message and hint. The current validator
must report the same, apart from the deliberate differences listed here. A definition
whose text changed since the recording is left out (its mutants are other documents).
"""

from __future__ import annotations

import gzip
import json

from tests.schema_corpus import FIXTURE, MUTANTS, SEED, corpus, diagnostics

# document id → (what the old validator said, what the new one says), for improvements.
_GENERAL = ([["E0203", 16, 7, 17, 1, "'general_annotations' must be a mapping, got str 'robotics-team'", ""]],
            [["E0203", 16, 7, 17, 1, "'general_annotations' must be a mapping or a list, got str "
              "'robotics-team'", ""]])
# general_annotations takes Phobos's list of pairs too (issue 29).
DELIBERATE: dict[str, tuple[list[list], list[list]]] = {
    "specs/annotations_categories#1: nesting ('model', 'annotations', 'general_annotations'); "
    "enum ('model', 'input_models', 'arm', 'basefile')": _GENERAL,
    "specs/annotations_categories#8: misspell ('model', 'annotations', 'named_annotations', 'thermal', "
    "'lower') -> lowe_r; nesting ('model', 'annotations', 'general_annotations')": _GENERAL}
# What the old validator never said: keys that have no effect where they stand (issue 20),
# warned of by the schema now; each kind has its own test in tests/compiler/broken/.
NEW_WARNINGS = {"W0250", "W0251", "W0252", "W0253", "W0255", "W0256", "W0257"}
# Export types added since the recording (`usd`, issue 32): messages that list the export types
# name them too; the lists are compared without them.
NEW_EXPORT_TYPES = ("usd",)


def _without_new_types(d: list) -> list:
    texts = [x for x in d if isinstance(x, str)]
    for t in NEW_EXPORT_TYPES:
        texts = [x.replace(f"'{t}', ", "").replace(f"{t}, ", "") for x in texts]
    it = iter(texts)
    return [next(it) if isinstance(x, str) else x for x in d]


def test_the_new_validator_reports_what_the_old_one_did() -> None:
    recorded = json.loads(gzip.decompress(FIXTURE.read_bytes()))
    assert (recorded["seed"], recorded["mutants"]) == (SEED, MUTANTS)
    expected, bases = recorded["documents"], recorded["bases"]
    compared, differences = 0, []
    for name, text_digest, doc in corpus():
        if bases.get(name.split("#")[0]) != text_digest:
            continue
        compared += 1
        got, want = diagnostics(doc), expected[name]
        got = [_without_new_types(d) for d in got if d[0] not in NEW_WARNINGS]
        if name in DELIBERATE:
            assert (want, got) == DELIBERATE[name], name
        elif got != want:
            differences.append(f"{name}\n  was: {want}\n  now: {got}")
    assert not differences, f"{len(differences)} documents differ:\n" + "\n".join(differences[:20])
    assert compared > 3000 and sum(map(len, expected.values())) > 4000
