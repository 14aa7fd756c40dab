"""Test results → the protocol: Markdown (a merge request's body), JSON, JUnit XML (CI test tabs).

A result is passed, failed, waived (failed, but the compare model is at the commit named
by `ignore_failing_tests_for`) or skipped (with the reason); skipped is never counted as
passed. The protocol fails when a test failed and was not waived.
"""

from __future__ import annotations

import json
import re
import shutil
from dataclasses import field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from mpc.backends import xml_escape
from mpc.core.record import record

if TYPE_CHECKING:
    from mpc.checks.pictures import VisualDiff

Status = Literal["passed", "failed", "waived", "skipped"]
# Characters XML 1.0 cannot hold, even escaped (a library's console may print them).
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_SIDES = ("release", "new", "overlay")  # the pictures of each view (checks/pictures.py)
_SIGN = {"passed": "✅ passed", "failed": "❌ failed", "waived": "⚠️ waived", "skipped": "⏭️ skipped"}


@record(slots=True)
class Tolerance:
    """A bound a figure was held to: `|figure| ≤ value` in `unit`, always absolute (a
    tolerance is never a fraction of the compared value). name: its key in `tolerances`."""

    name: str
    value: float
    unit: str

    def __str__(self) -> str:
        return f"`{self.name}` ≤ {self.value:g}{' ' + self.unit if self.unit else ''}"


@record(slots=True, kw_only=True)
class Result:
    """The outcome of one test.

    name: the test's definition name (`compare_com`, …), with ` 2`, ` 3` for repeats.
    status: passed / failed / waived / skipped. reason: why, in one sentence.
    figure: the measured value the verdict rests on (the worst one), with `unit`.
    tolerances: the bounds it was held to (absolute; two for a pose: distance and angle);
    none for an exact comparison or a test without a figure.
    details: lines for the protocol (per link, per joint …), worst first.
    log: what a library printed meanwhile (PyBullet's console).
    """

    name: str
    status: Status
    reason: str = ""
    figure: float | None = None
    unit: str = ""
    tolerances: tuple[Tolerance, ...] = ()
    details: tuple[str, ...] = ()
    log: str = ""

    @property
    def failed(self) -> bool:
        return self.status == "failed"


def passed(name: str, reason: str = "", **kw: object) -> Result:
    return Result(name=name, status="passed", reason=reason, **kw)  # type: ignore[arg-type]


def failed(name: str, reason: str, **kw: object) -> Result:
    return Result(name=name, status="failed", reason=reason, **kw)  # type: ignore[arg-type]


def skipped(name: str, reason: str, **kw: object) -> Result:
    return Result(name=name, status="skipped", reason=reason, **kw)  # type: ignore[arg-type]


def verdict(name: str, ok: bool, reason: str, **kw: object) -> Result:
    return (passed if ok else failed)(name, reason, **kw)


@record(slots=True, frozen=False)
class Protocol:
    """Every test's result of one model, in the order they ran."""

    model: str
    results: list[Result] = field(default_factory=list)
    compare: str = ""  # what the model was compared with (repository @ commit, or folder)
    waiver: str = ""  # why failures are waived, when they are
    pictures: VisualDiff | None = None  # the visual diff against the compare model
    # the model diff against the compare model (checks/diff_models.py): each change beyond the
    # tolerances, in the diff's words; None when there was nothing to compare with
    changes: tuple[str, ...] | None = None

    def add(self, result: Result) -> None:
        """Record `result`; a repeated name gets a suffix; a failure becomes a waiver when
        the compare model is at the commit that `ignore_failing_tests_for` names."""
        names = {r.name for r in self.results}
        name, n = result.name, 1
        while name in names:
            n += 1
            name = f"{result.name} {n}"
        if result.status == "failed" and self.waiver:
            result = replace(result, status="waived", reason=f"{result.reason} (waived: {self.waiver})")
        self.results.append(replace(result, name=name))

    @property
    def failed(self) -> bool:
        """Whether a test failed and was not waived."""
        return any(r.failed for r in self.results)

    def counts(self) -> dict[str, int]:
        statuses = ("passed", "failed", "waived", "skipped")
        return {s: sum(r.status == s for r in self.results) for s in statuses}

    def summary(self) -> str:
        c = self.counts()
        return ", ".join(f"{n} {s}" for s, n in c.items() if n or s in ("passed", "failed"))

    # -- renderers ---------------------------------------------------------------------

    def markdown(self) -> str:
        verdict_line = "**failed**" if self.failed else "**passed**"
        lines = [f"## Model tests of `{self.model}`: {verdict_line} ({self.summary()})", ""]
        if self.compare:
            lines += [f"Compared with {self.compare}.", ""]
        if self.changes is not None:
            n = len(self.changes)
            lines += [f"**{n} change{'s' * (n != 1)}** beyond the tolerances (`mpc diff`)"
                      + (":" if n else "."), ""]
            if n:
                from mpc.checks.diff_report import code_spans

                lines += [*(f"- {code_spans(c)}" for c in self.changes), ""]
        if self.waiver:
            lines += [f"Failures are waived: {self.waiver}.", ""]
        lines += ["| test | result | figure | tolerance | reason |", "|---|---|---|---|---|"]
        for r in self.results:
            lines.append(f"| `{r.name}` | {_SIGN[r.status]} | {_figure(r)} | {_tolerance(r)} | "
                         f"{_cell(r.reason)} |")
        lines += self._pictures_markdown()
        for r in self.results:
            if r.details or r.log:
                lines += ["", f"<details><summary><code>{r.name}</code></summary>", "", "```"]
                lines += list(r.details)
                if r.log:
                    lines += ["--- output ---", r.log.rstrip()]
                lines += ["```", "", "</details>"]
        return "\n".join(lines) + "\n"

    def _pictures_markdown(self) -> list[str]:
        """The visual diff: per view the release, the new model and both overlaid."""
        p = self.pictures
        if p is None:
            return []
        tree = [] if not p.tree else [
            "", f"The kinematic tree, changed links in orange: [{p.tree}]({p.tree})"]
        if p.problem:
            return ["", f"No pictures: {_cell(p.problem)}", *tree]
        changed = ", ".join(f"`{link}` ({why})" for link, why in p.changed.items()) or "none"
        lines = ["", "### Pictures", "", "Links changed beyond the tolerances are coloured (blue in the "
                 "release, orange in the new model); the others are grey. The overlay shows both.",
                 "", f"Changed links: {_cell(changed)}.", *[line for n in p.notes for line in ("", n)],
                 "", "| view | release | new | overlay |",
                 "|---|---|---|---|"]
        for view in p.views:
            cells = " | ".join(f"![{view}, {side}]({p.path(view, side)})" for side in _SIDES)
            lines.append(f"| {view} | {cells} |")
        return lines + tree

    def picture_files(self) -> list[str]:
        """The pictures' paths, relative to the protocol."""
        p = self.pictures
        if p is None:
            return []
        return [p.path(v, s) for v in p.views for s in _SIDES if p.drawn] + ([p.tree] if p.tree else [])

    def to_json(self) -> dict[str, object]:
        p = self.pictures
        pictures = None if p is None else {
            "views": {v: {s: p.path(v, s) for s in _SIDES} for v in p.views} if p.drawn else {},
            "kinematic_tree": p.tree or None, "changed_links": p.changed, "problem": p.problem,
            "notes": p.notes}
        return {
            "model": self.model, "failed": self.failed, "counts": self.counts(),
            "compare": self.compare, "waiver": self.waiver, "pictures": pictures,
            "changes": None if self.changes is None else list(self.changes),
            "tests": [{"name": r.name, "status": r.status, "reason": r.reason, "figure": r.figure,
                       "unit": r.unit, "tolerances": [{"name": t.name, "value": t.value, "unit": t.unit,
                                                       "kind": "absolute"} for t in r.tolerances],
                       "details": list(r.details), "log": r.log} for r in self.results],
        }

    def junit(self) -> str:
        c = self.counts()
        out = ['<?xml version="1.0" encoding="UTF-8"?>',
               f'<testsuites name="mpc test" tests="{len(self.results)}" failures="{c["failed"]}">',
               f'  <testsuite name={_xml_attribute(self.model)} tests="{len(self.results)}" '
               f'failures="{c["failed"]}" skipped="{c["skipped"] + c["waived"]}" errors="0">']
        files = self.picture_files()
        if files:
            out.append("    <properties>")
            out += [f'      <property name="picture" value={_xml_attribute(f)}/>' for f in files]
            out.append("    </properties>")
        for r in self.results:
            head = f'    <testcase classname={_xml_attribute(self.model)} name={_xml_attribute(r.name)}'
            measured = [] if r.figure is None else [f"{_figure(r)} (tolerance {_tolerance(r) or 'none'})"]
            text = "\n".join([*measured, *r.details])
            if r.status == "passed" and not r.log:
                out.append(head + "/>")
                continue
            out.append(head + ">")
            if r.status == "failed":
                out.append(f"      <failure message={_xml_attribute(r.reason)}>{_xml_text(text)}</failure>")
            elif r.status in ("skipped", "waived"):
                out.append(f"      <skipped message={_xml_attribute(r.status + ': ' + r.reason)}/>")
            if r.log:
                out.append(f"      <system-out>{_xml_text(r.log)}</system-out>")
            out.append("    </testcase>")
        if files:  # GitLab's and Jenkins's way of attaching files to a report
            out.append(f"    <system-out>{_xml_text(chr(10).join(f'[[ATTACHMENT|{f}]]' for f in files))}"
                       "</system-out>")
        out += ["  </testsuite>", "</testsuites>"]
        return "\n".join(out) + "\n"

    def write(self, folder: Path) -> None:
        """Write test_protocol.md, test_protocol.json and test_protocol.junit.xml into `folder`."""
        from mpc.core.files import write_atomic

        folder.mkdir(parents=True, exist_ok=True)  # its error names the folder as the user gave it
        write_atomic(folder / "test_protocol.md", self.markdown())
        write_atomic(folder / "test_protocol.json", json.dumps(self.to_json(), indent=2) + "\n")
        write_atomic(folder / "test_protocol.junit.xml", self.junit())
        self._write_pictures(folder)

    def _write_pictures(self, folder: Path) -> None:
        """The pictures into `folder/test_pictures/`, replacing those of an earlier run (a
        symbolic link there is removed, not followed)."""
        from mpc.checks.pictures import FOLDER

        target = folder / FOLDER
        if target.is_symlink() or target.is_file():
            target.unlink()
        elif target.exists():
            shutil.rmtree(target)
        if self.pictures is None or not self.pictures.files:  # pictures, or the tree alone
            return
        target.mkdir()
        for name, data in sorted(self.pictures.files.items()):
            (target / name).write_bytes(data)


def first_of(problems: list[str]) -> str:
    """The first problem, and how many more there are: a reason for the protocol's table."""
    return problems[0] + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else "")


def counted(n: float, noun: str, plural: str = "") -> str:
    """`1 joint`, `2 joints`: a count with its noun (plural: when it is not noun + s)."""
    return f"{n:g} {noun if n == 1 else plural or noun + 's'}"


def vector_text(v: object) -> str:
    """A 3-vector for a reason: (0.1, -0.2, 0.3), four significant digits."""
    return "(" + ", ".join(f"{float(x):.4g}" for x in v) + ")"  # type: ignore[attr-defined]


def _xml_text(text: str) -> str:
    """`text` escaped for XML content, with characters XML cannot hold dropped."""
    return xml_escape.text(_NOT_XML.sub("", text))


def _xml_attribute(text: str) -> str:
    return '"' + xml_escape.attribute(_NOT_XML.sub("", text)) + '"'


def _figure(r: Result) -> str:
    return "" if r.figure is None else f"{r.figure:.6g}{' ' + r.unit if r.unit else ''}"


def _tolerance(r: Result) -> str:
    return ", ".join(map(str, r.tolerances)) + " (absolute)" if r.tolerances else ""


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")
