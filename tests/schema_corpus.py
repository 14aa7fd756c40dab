"""The schema differential's corpus: every definition of the repository and seeded mutations.

Documents: examples/, the ```yaml examples of specs/, and the definitions under tests/
(`model:` or `pipeline:` at the top), each loaded and with its `defaults` merged. Mutations:
edits of the loaded data (delete a key, misspell a key, a value of the wrong type, an enum
value one letter off, a list for a scalar and back, a value nested one level too deep or
too shallow), one to three per document, drawn from a fixed seed. The spans of a renamed
key are those of the key it replaces, so the mutated document needs no YAML text.

tests/fixtures/schema/diagnostics.json.gz holds what the validator reported for this corpus
when it was recorded (`python -m tests.schema_corpus record`), and
tests/compiler/test_schema_differential.py compares the current validator with it.
"""

from __future__ import annotations

import copy
import gzip
import hashlib
import json
import random
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
FIXTURE = ROOT / "tests/fixtures/schema/diagnostics.json.gz"
SEED = 20
MUTANTS = 16  # per document

WRONG_VALUES: tuple[Any, ...] = (5, 2.5, "text", True, None, [1, 2], {"a": 1}, [], {})


def digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _sources() -> Iterator[tuple[str, str, Path]]:
    """(name, YAML text, the file it stands for) of every definition and pipeline file."""
    for folder in ("examples", "tests"):
        for path in sorted((ROOT / folder).rglob("*.y*ml")):
            if path.suffix in (".yml", ".yaml") and ".venv" not in path.parts:
                text = path.read_text(errors="replace")
                if re.search(r"^(model|pipeline):", text, re.M):
                    yield str(path.relative_to(ROOT)), text, path
    for page in sorted((ROOT / "specs").glob("*.md")):
        for block in re.findall(r"```yaml\n(.*?)```", page.read_text(), re.DOTALL):
            m = re.match(r"# example: (\S+)", block)
            if m and re.search(r"^(model|pipeline):", block, re.M):
                yield f"specs/{m.group(1)}", block, ROOT / "specs/examples" / f"{m.group(1)}.yml"


def base_documents() -> list[tuple[str, str, Any]]:
    """(name, digest of its text, Document) of every source that loads (the YAML's own
    errors are not the schema's)."""
    from mpc.compiler import inherit
    from mpc.core import yaml_source as source
    from mpc.core.diagnostics import Sink

    out = []
    for name, text, path in _sources():
        sink = Sink()
        doc = source.loads(text, name, sink)
        if doc is None or sink.has_errors() or not isinstance(doc.data, dict):
            continue
        if "model" in doc.data:
            doc = inherit.resolve(doc, path, sink)
            if doc is None or sink.has_errors():
                continue
        out.append((name, digest(text), doc))
    return out


def _clone(doc: Any) -> Any:
    from mpc.core.yaml_source import Document

    return Document(doc.file, copy.deepcopy(doc.data), dict(doc.values), dict(doc.keys))


def _keyed_paths(data: Any, path: tuple = ()) -> Iterator[tuple]:
    if isinstance(data, dict):
        for k, v in data.items():
            yield (*path, k)
            yield from _keyed_paths(v, (*path, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _keyed_paths(v, (*path, i))


def _misspell(word: str, rng: random.Random) -> str:
    i = rng.randrange(len(word) + 1)
    op = rng.choice(("drop", "add", "swap", "change"))
    if op == "drop" and len(word) > 1:
        return word[:i - 1] + word[i:] if i else word[1:]
    if op == "swap" and len(word) > 2:
        i = min(i, len(word) - 2)
        return word[:i] + word[i + 1] + word[i] + word[i + 2:]
    letter = rng.choice("aeiorstlnx_")
    if op == "change" and i < len(word):
        return word[:i] + letter + word[i + 1:]
    return word[:i] + letter + word[i:]


def _rekey(doc: Any, old: tuple, new: tuple) -> None:
    n = len(old)
    for table in (doc.values, doc.keys):
        for p in [p for p in table if p[:n] == old]:
            table[(*new, *p[n:])] = table[p]


def _mutate(doc: Any, rng: random.Random) -> str:
    """One edit of the document's data; what it did, for the record."""
    paths = list(_keyed_paths(doc.data))
    if not paths:
        return "nothing"
    path = rng.choice(paths)
    parent = doc.data_at(path[:-1])
    key = path[-1]
    value = parent[key]
    op = rng.choice(("delete", "misspell", "wrong_type", "wrong_type", "enum", "list_scalar", "nesting"))
    if op == "delete" and isinstance(parent, dict):
        del parent[key]
    elif op == "misspell" and isinstance(parent, dict) and isinstance(key, str) and key:
        new = _misspell(key, rng)
        if new in parent:
            return "nothing"
        items = list(parent.items())
        parent.clear()
        parent.update((new if k == key else k, v) for k, v in items)
        _rekey(doc, (*path[:-1], key), (*path[:-1], new))
        return f"misspell {path} -> {new}"
    elif op == "enum" and isinstance(value, str) and value:
        parent[key] = _misspell(value, rng)
    elif op == "list_scalar":
        parent[key] = value[0] if isinstance(value, list) and value else [value]
    elif op == "nesting":
        if isinstance(value, dict) and value and rng.random() < 0.5:
            parent[key] = next(iter(value.values()))
        else:
            parent[key] = {str(key): value}
    else:
        op = "wrong_type"
        parent[key] = copy.deepcopy(rng.choice(WRONG_VALUES))
    return f"{op} {path}"


def corpus() -> Iterator[tuple[str, str, Any]]:
    """(id, digest of the base's text, Document): each base document, then its seeded
    mutants (drawn from the seed and the base's name, so that other files do not change them)."""
    for name, text_digest, base in base_documents():
        yield name, text_digest, _clone(base)
        rng = random.Random(f"{SEED}:{name}")
        for n in range(MUTANTS):
            doc = _clone(base)
            edits = [_mutate(doc, rng) for _ in range(rng.choice((1, 1, 2, 3)))]
            yield f"{name}#{n}: " + "; ".join(edits), text_digest, doc


def diagnostics(doc: Any) -> list[list[Any]]:
    """What the validator reports about a document, in a canonical order."""
    from mpc.compiler import schema
    from mpc.core.diagnostics import Sink

    sink = Sink()
    if "pipeline" in doc.data and "model" not in doc.data:
        schema.validate_pipeline(doc, sink)
    else:
        schema.validate(doc, sink)
    return sorted([d.code, d.span.line, d.span.col, d.span.end_line, d.span.end_col, d.message,
                   d.hint or ""] for d in sink)


def record() -> None:
    documents, bases = {}, {}
    for name, text_digest, doc in corpus():
        documents[name] = diagnostics(doc)
        bases[name.split("#")[0]] = text_digest
    out = {"seed": SEED, "mutants": MUTANTS, "bases": bases, "documents": documents}
    FIXTURE.parent.mkdir(parents=True, exist_ok=True)
    with gzip.open(FIXTURE, "wt", compresslevel=9) as f:
        json.dump(out, f, separators=(",", ":"), sort_keys=True)
    print(f"{len(out['documents'])} documents recorded in {FIXTURE.relative_to(ROOT)}")


if __name__ == "__main__" and sys.argv[1:] == ["record"]:
    record()
