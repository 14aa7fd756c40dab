"""Events of a run → what the user sees while it runs: a live display on a terminal (rich),
nothing when the output is not a terminal, or one JSON object a line (`--log-format json`).

The live display refreshes from the runner's loop (no refresh thread), so that forking a
worker never copies a thread holding a lock.
"""

from __future__ import annotations

import json
import sys
import time
from typing import IO, Any

from mpc.pipeline.status import ModelRecord, RunStatus, model_state, record_json


class Quiet:
    """Shows nothing while running; the table at the end says everything."""

    def planned(self, status: RunStatus, models: list[str]) -> None:
        pass

    def started(self, model: str, pid: int) -> None:
        pass

    def finished(self, model: str, record: ModelRecord) -> None:
        pass

    def tick(self) -> None:
        pass

    def close(self) -> None:
        pass


class JsonLog(Quiet):
    """One JSON object a line on `stream`: plan, start (with the worker's pid), finish, end."""

    def __init__(self, stream: IO[str] | None = None) -> None:
        self.stream = stream or sys.stdout

    def emit(self, event: str, **fields: Any) -> None:
        self.stream.write(json.dumps({"event": event, "time": round(time.time(), 3), **fields},
                                     sort_keys=True) + "\n")
        self.stream.flush()

    def planned(self, status: RunStatus, models: list[str]) -> None:
        self.emit("plan", pipeline=status.pipeline, models=models, stages=list(status.stages),
                  jobs=status.jobs)

    def started(self, model: str, pid: int) -> None:
        self.emit("start", model=model, pid=pid)

    def finished(self, model: str, record: ModelRecord) -> None:
        self.emit("finish", model=model, state=model_state(record),
                  stages={s: record_json(r) for s, r in record.stages.items()})


_MARK = {"ok": "[green]✓[/]", "cached": "[dim]=[/]", "failed": "[red]✗[/]", "skipped": "[yellow]-[/]",
         "interrupted": "[red]![/]"}


class Live(Quiet):
    """A rich progress display on stderr: a bar over all models, a line per running build,
    and a line per finished model above them."""

    def __init__(self) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            SpinnerColumn,
            TextColumn,
            TimeElapsedColumn,
        )

        self.console = Console(stderr=True)
        self.progress = Progress(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(),
                                 MofNCompleteColumn(), TimeElapsedColumn(), console=self.console,
                                 auto_refresh=False, transient=True)
        self.total: Any = None
        self.tasks: dict[str, Any] = {}

    def planned(self, status: RunStatus, models: list[str]) -> None:
        self.progress.start()
        self.total = self.progress.add_task(f"{len(models)} models", total=len(models))

    def started(self, model: str, pid: int) -> None:
        self.tasks[model] = self.progress.add_task(f"  {model}", total=None)
        self.progress.refresh()

    def finished(self, model: str, record: ModelRecord) -> None:
        if model in self.tasks:
            self.progress.remove_task(self.tasks.pop(model))
        state = model_state(record)
        note = next((r.summary for r in record.stages.values() if r.summary and r.state == state), "")
        self.progress.console.print(f"{_MARK.get(state, ' ')} {model} [dim]{state}[/] {note}",
                                    highlight=False, markup=True, soft_wrap=True)
        self.progress.advance(self.total)
        self.progress.refresh()

    def tick(self) -> None:
        self.progress.refresh()

    def close(self) -> None:
        self.progress.stop()


def reporter(log_format: str, stream: IO[str] | None = None) -> Quiet:
    """The reporter for `--log-format` and the kind of output."""
    if log_format == "json":
        return JsonLog(stream)
    return Live() if sys.stderr.isatty() else Quiet()


def rich_table(status: RunStatus) -> None:
    """The end-of-run table on stdout, in colour."""
    from rich.console import Console
    from rich.table import Table

    from mpc.pipeline.status import summary_line, table_rows

    header, *rows = table_rows(status)
    table = Table(*header, box=None, pad_edge=False)
    for row in rows:
        cells = [row[0], *(f"{_MARK.get(c, '')} {c}" for c in row[1:-2]), row[-2], row[-1]]
        table.add_row(*cells)
    console = Console()
    console.print(table, highlight=False)
    console.print(summary_line(status), highlight=False)
