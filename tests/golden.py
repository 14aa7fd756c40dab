"""Recorded outputs: what a test found, against what mpc gave when the record was made.

A golden test turns each of its cases into text that does not depend on the machine
(`stable`: the folders of example-robot-data, of this checkout and of the test's tmp folder
are written `$ERD`, `$REPO`, `$TMP`, the process id `$PID`; floats are Python's repr, the
shortest text that reads back as the same float, the same on every IEEE-754 machine), and
compares the SHA-256 of each case with tests/fixtures/golden/NAME.json (the first 16 hex
digits: enough to see a change, small enough to review). A few readable cases are kept
whole (`check_text`, NAME.txt).

`MPC_UPDATE_GOLDEN=1` records them again (as in test_mesh_bytes.py); only that rewrites a
record, and the diff of the fixture then shows which cases changed.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from mpc.core.diagnostics import Diagnostic
from mpc.core.record import record_fields
from tests.conftest import ERD

FIXTURES = Path(__file__).resolve().parent / "fixtures" / "golden"
REPO = Path(__file__).resolve().parents[1]
UPDATE = os.environ.get("MPC_UPDATE_GOLDEN") == "1"


def stable(text: str, tmp: Path | None = None) -> str:
    """`text` with the machine's folders named by placeholders, longest first (ERD may be
    installed inside the checkout, the tmp folder too)."""
    roots = [(str(ERD.resolve()), "$ERD"), (str(ERD), "$ERD"), (str(REPO), "$REPO")]
    if tmp is not None:
        roots += [(str(tmp.resolve()), "$TMP"), (str(tmp), "$TMP")]
    for root, name in sorted(roots, key=lambda r: -len(r[0])):
        text = text.replace(root, name)
    # /proc/self is this process: mpc names the file it is (E0650), with the process id.
    return text.replace(f"/proc/{os.getpid()}/", "/proc/$PID/")


def value_lines(value: object) -> list[str]:
    """A record (a Robot, …) as lines: one per field, one per entry of a dict field; every
    value its repr (all fields, spans resolved)."""
    if value is None:
        return ["None"]
    lines = [type(value).__name__]
    for name in record_fields(type(value)):
        field = getattr(value, name)
        if isinstance(field, Mapping):
            lines += [f"{name}[{key!r}] = {item!r}" for key, item in field.items()] or [f"{name} = {{}}"]
        else:
            lines.append(f"{name} = {field!r}")
    return lines


def diagnostic_lines(diagnostics: Iterable[Diagnostic]) -> list[str]:
    """Each diagnostic whole: severity, code, span (with its end), message, notes, hint."""
    return [f"{d.severity.value} {d.code} {d.span!r}: {d.message} | notes={d.notes!r} | hint={d.hint!r}"
            for d in diagnostics]


def digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:16]


def check_digests(name: str, found: Mapping[str, str]) -> None:
    """Every case's digest equals the recorded one, and no case is new or gone."""
    path = FIXTURES / f"{name}.json"
    if UPDATE:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(dict(sorted(found.items())), indent=0, ensure_ascii=False) + "\n")
    assert path.exists(), f"no record {path.relative_to(REPO)}: make it with MPC_UPDATE_GOLDEN=1"
    recorded = json.loads(path.read_text())
    changed = sorted(k for k in found.keys() & recorded.keys() if found[k] != recorded[k])
    new, gone = sorted(found.keys() - recorded.keys()), sorted(recorded.keys() - found.keys())
    assert (changed, new, gone) == ([], [], []), \
        f"{path.name}: {len(changed)} changed {changed[:20]}, new {new[:20]}, gone {gone[:20]}"


def check_text(name: str, text: str) -> None:
    """`text` equals the recorded tests/fixtures/golden/NAME.txt."""
    path = FIXTURES / f"{name}.txt"
    if UPDATE:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text.encode("utf-8", "surrogatepass"))
    assert path.exists(), f"no record {path.relative_to(REPO)}: make it with MPC_UPDATE_GOLDEN=1"
    assert text == path.read_bytes().decode("utf-8", "surrogatepass"), f"{path.name} differs"
