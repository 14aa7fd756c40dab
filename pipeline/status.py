"""Outcomes of a run → records per model and stage, status.json, the end-of-run table, the exit status.

States: `ok`, `cached` (unchanged since a run where it succeeded), `failed` (with its
diagnostics), `skipped` (with the reason: a stage or a parent it needs did not succeed, or
the stage had nothing to do), `interrupted` (the run was stopped).
"""

from __future__ import annotations

import json
from dataclasses import field
from typing import Any

from mpc.core.diagnostics import Diagnostic, Severity
from mpc.core.record import record

GOOD = ("ok", "cached")


@record(frozen=False)
class StageRecord:
    """One stage of one model in this run.

    blocked: skipped because something it needs failed (not by the stage's own choice).
    """

    state: str
    summary: str = ""
    diagnostics: list[Diagnostic] = field(default_factory=list)
    seconds: float = 0.0
    fingerprint: str | None = None
    details: dict[str, Any] = field(default_factory=dict)
    blocked: bool = False


@record(frozen=False)
class ModelRecord:
    """A model of this run: its definition, parents and the record of each selected stage;
    for a model a worker built, when the worker started (seconds since the run started) and
    its wall time, until the worker ended."""

    name: str
    definition: str
    parents: tuple[str, ...]
    stages: dict[str, StageRecord] = field(default_factory=dict)
    warnings: list[Diagnostic] = field(default_factory=list)  # from planning
    started: float | None = None
    seconds: float | None = None

    @property
    def failed(self) -> bool:
        return any(r.state == "failed" for r in self.stages.values())

    def diagnostics(self) -> list[Diagnostic]:
        return [*self.warnings, *(d for r in self.stages.values() for d in r.diagnostics)]


@record(frozen=False)
class RunStatus:
    """The whole run, in the order models finished."""

    pipeline: str
    stages: tuple[str, ...]
    jobs: int
    models: dict[str, ModelRecord] = field(default_factory=dict)
    seconds: float = 0.0
    interrupted: bool = False
    internal_error: bool = False

    def exit_status(self, verify: bool = False, allow_na: bool = False) -> int:
        """0 when every selected model succeeded; 1 when one failed (or, with `verify`, when a
        selected stage of a selected model is not ok or cached; `allow_na` lets stages that
        skipped by their own choice pass); 3 when mpc itself failed; 130 when interrupted."""
        if self.internal_error:
            return 3
        if self.interrupted:
            return 130
        records = [r for m in self.models.values() for r in m.stages.values()]
        if any(r.state == "failed" for r in records):
            return 1
        if verify and any(r.state not in GOOD and (r.blocked or not allow_na) for r in records):
            return 1
        return 0

    def counts(self) -> dict[str, int]:
        """How many models ended in each state (a model's state: its worst stage)."""
        out: dict[str, int] = {}
        for m in self.models.values():
            state = model_state(m)
            out[state] = out.get(state, 0) + 1
        return out

    def to_json(self, verify: bool = False, allow_na: bool = False) -> dict[str, Any]:
        return {
            "version": 1,
            "pipeline": self.pipeline,
            "stages": list(self.stages),
            "jobs": self.jobs,
            "seconds": round(self.seconds, 3),
            "exit_status": self.exit_status(verify, allow_na),
            "counts": self.counts(),
            "models": {
                name: {
                    "definition": m.definition,
                    "parents": list(m.parents),
                    "state": model_state(m),
                    "warnings": diagnostics_json(m.warnings),
                    "stages": {stage: record_json(r) for stage, r in m.stages.items()},
                    **({"started": round(m.started, 3)} if m.started is not None else {}),
                    **({"seconds": round(m.seconds, 3)} if m.seconds is not None else {}),
                }
                for name, m in self.models.items()
            },
        }


def model_state(model: ModelRecord) -> str:
    """The worst state of its stages: failed, interrupted, skipped, ok, cached."""
    states = {r.state for r in model.stages.values()}
    return next((s for s in ("failed", "interrupted", "skipped", "ok") if s in states), "cached")


def record_json(r: StageRecord) -> dict[str, Any]:
    out: dict[str, Any] = {"state": r.state, "seconds": round(r.seconds, 3)}
    if r.summary:
        out["reason" if r.state in ("skipped", "interrupted") else "summary"] = r.summary
    if r.fingerprint:
        out["fingerprint"] = r.fingerprint
    if r.diagnostics:
        out["diagnostics"] = diagnostics_json(r.diagnostics)
    if r.details:
        out["details"] = r.details
    return out


def diagnostics_json(diagnostics: list[Diagnostic]) -> list[Any]:
    from mpc.core import render

    return json.loads(render.as_json(diagnostics)) if diagnostics else []


def diagnostics_from_json(items: list[Any]) -> list[Diagnostic]:
    """Diagnostics as `diagnostics_json` wrote them (a failure replayed from the state)."""
    from mpc.core.span import Span

    def span(d: dict[str, Any] | None) -> Span | None:
        return None if d is None else Span(d["file"], d["line"], d["col"], d["end_line"], d["end_col"])

    return [Diagnostic(Severity(d["severity"]), d["code"], d["message"], span(d["span"]) or Span(""),
                       tuple((span(n["span"]), n["message"]) for n in d["notes"]), d["hint"]) for d in items]


def past(state: str) -> str:
    """A stage's state as the reason its dependants give: "derived_base 'x' failed"."""
    return {"failed": "failed", "skipped": "was skipped", "interrupted": "was interrupted"}.get(state, state)


def model_from_json(name: str, data: dict[str, Any]) -> ModelRecord:
    """A model's record as `RunStatus.to_json` wrote it (a CI job's record, for the summary)."""
    stages = {stage: StageRecord(r["state"], r.get("summary") or r.get("reason", ""),
                                 diagnostics_from_json(r.get("diagnostics", [])), r.get("seconds", 0.0),
                                 r.get("fingerprint"), r.get("details", {}))
              for stage, r in data["stages"].items()}
    return ModelRecord(name, data["definition"], tuple(data["parents"]), stages,
                       diagnostics_from_json(data.get("warnings", [])))


def table_rows(status: RunStatus) -> list[list[str]]:
    """Header and one row per model: name, each stage's state, time, what to know."""
    rows = [["model", *status.stages, "time", "note"]]
    for m in sorted(status.models.values(), key=lambda m: m.name):
        note = next((r.summary for r in m.stages.values() if r.state not in GOOD and r.summary), "")
        if not note:
            note = next((r.summary for r in m.stages.values() if r.summary), "")
        seconds = sum(r.seconds for r in m.stages.values())
        rows.append([m.name, *(m.stages[s].state if s in m.stages else "-" for s in status.stages),
                     f"{seconds:.1f}s" if seconds else "", note])
    return rows


def plain_table(status: RunStatus, width: int = 100) -> str:
    rows = table_rows(status)
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    lines = []
    for row in rows:
        cells = [c.ljust(w) for c, w in zip(row, widths, strict=False)]
        line = "  ".join([*cells, row[-1]])
        lines.append(line if len(line) <= width else line[: width - 1] + "…")
    return "\n".join(lines) + "\n" + summary_line(status)


def summary_line(status: RunStatus) -> str:
    counts = status.counts()
    parts = [f"{n} {state}" for state, n in sorted(counts.items(), key=lambda kv: _ORDER.index(kv[0]))]
    total = sum(counts.values())
    return f"{total} model{'s' * (total != 1)}: {', '.join(parts)} in {status.seconds:.1f} s"


def markdown_table(status: RunStatus) -> str:
    """The table as Markdown (a GitHub job summary, a merge request)."""
    rows = table_rows(status)
    lines = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
    lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in rows[1:]]
    return "\n".join(lines) + "\n\n" + summary_line(status) + "\n"


_ORDER = ["ok", "cached", "failed", "skipped", "interrupted"]

