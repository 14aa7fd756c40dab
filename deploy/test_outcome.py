"""The model's tests as a deployment knows them: passed, failed or not run, and the protocol.

A deployment decides by the tests, not by how it was called: the caller's protocol (the
pipeline's test stage, `mpc deploy --protocol`) when given, else the one `mpc test` wrote
into the build (`test_protocol.json`, and `test_protocol.md` for the merge request). A
protocol that says its tests failed sends the model to the failure branch whether or not
the caller said so; one that cannot be read stops the deployment (E0860), since pushing a
failed model to the success branch cannot be undone by a later run.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from mpc.core.record import record
from mpc.deploy.gitcmd import DeployError

JSON, MARKDOWN = "test_protocol.json", "test_protocol.md"
STATUSES = ("passed", "failed", "waived", "skipped")
# The first line of mpc's Markdown protocol (checks/protocol.py): `## Model tests of `m`: **failed** (…)`
_VERDICT = re.compile(r"\A## Model tests of .*: \*\*(passed|failed)\*\*")
_COUNTS = re.compile(r"\b\d+ (?:passed|failed|skipped)\b(?:[,;]? *\d+ (?:passed|failed|skipped)\b)*")


@record
class TestOutcome:
    """failed: the model goes to the failure branch. markdown: the protocol for the merge
    request, if any. counts: `3 passed, 1 failed`, when known. ran: whether a protocol
    (or the caller) says the tests ran."""

    failed: bool
    markdown: str | None = None
    counts: str = ""
    ran: bool = False

    def summary(self) -> str:
        """`passed` / `failed` / `not run`, with the counts when known (the commit's `Tests:` line)."""
        if not self.ran:
            return "failed" if self.failed else "not run"
        outcome = "failed" if self.failed else "passed"
        return f"{outcome} ({self.counts})" if self.counts else outcome


def test_outcome(built: Path, markdown: str | None, tests_failed: bool) -> TestOutcome:
    """What the caller says (`markdown`, `tests_failed`), else what the build's protocol says."""
    if markdown is not None:
        return _of_markdown(markdown, tests_failed)
    data = _build_json(built / JSON)
    if data is not None:
        failed, counts = data
        text = _text(built / MARKDOWN) if (built / MARKDOWN).is_file() else None
        return TestOutcome(failed or tests_failed, text, counts, ran=True)
    if (built / MARKDOWN).is_file():
        return _of_markdown(_text(built / MARKDOWN), tests_failed)
    return TestOutcome(tests_failed)


def _of_markdown(text: str, tests_failed: bool) -> TestOutcome:
    verdict = _VERDICT.match(text)
    counts = _COUNTS.search(text)
    failed = tests_failed or (verdict is not None and verdict.group(1) == "failed")
    return TestOutcome(failed, text, counts.group(0) if counts else "", ran=True)


def _text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except OSError as e:
        problem = e.strerror or str(e)
    except UnicodeDecodeError as e:
        problem = f"it is not UTF-8 text (byte 0x{e.object[e.start]:02x} at offset {e.start})"
    raise DeployError("E0860", f"cannot read the build's test protocol '{path}': {problem}")


def _build_json(path: Path) -> tuple[bool, str] | None:
    """(failed, counts) of the build's test_protocol.json; None when there is none."""
    if not path.is_file():
        return None
    text = _text(path)
    try:
        data = json.loads(text)
    except ValueError as e:
        raise DeployError("E0860", f"the build's test protocol '{path}' is not JSON: {e}") from None
    failed = data.get("failed") if isinstance(data, dict) else None
    counts = data.get("counts") if isinstance(data, dict) else None
    if not isinstance(failed, bool) or not isinstance(counts, dict) or not all(
            isinstance(counts.get(s, 0), int) and not isinstance(counts.get(s, 0), bool) for s in STATUSES):
        raise DeployError("E0860", f"the build's test protocol '{path}' is not one that `mpc test` "
                          "writes: it needs `failed` (true or false) and `counts` of passed, failed, "
                          "waived and skipped tests")
    shown = ", ".join(f"{counts.get(s, 0)} {s}" for s in STATUSES
                      if counts.get(s, 0) or s in ("passed", "failed"))
    return failed, shown
