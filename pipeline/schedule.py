"""The models of a run, their last build times and sources → the order `mpc run` starts them in.

The longest remaining path first: a model's priority is its own expected time plus the
longest chain of expected times among the models that wait for it, so the chain that
decides when the run ends starts first. The expected time is the model's last wall time
(status.json) or the sum of its last stage times (its state); models never built count the
median of the known times (1 s when none is known). Among the models ready to start, one
that shares no source file (a `basefile`, whose meshes it converts) with a running model
goes first, so that two workers do not convert the same meshes at once when another model
can use the worker. Pure functions; the runner reads the inputs.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from mpc.core.files import resolved
from mpc.pipeline import dag

UNKNOWN_SECONDS = 1.0  # a model's expected time when no model of the pipeline was ever built


def _median(ordered: Sequence[float]) -> float:
    """The median of sorted numbers (not `statistics`: its imports cost a run where all is cached)."""
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else (ordered[mid - 1] + ordered[mid]) / 2


def expected_seconds(models: Iterable[str], known: Mapping[str, float]) -> dict[str, float]:
    """Each model's expected build time: its known time, or the median of the known ones."""
    times = sorted(t for t in known.values() if t > 0)
    default = _median(times) if times else UNKNOWN_SECONDS
    return {n: known[n] if known.get(n, 0) > 0 else default for n in models}


def priorities(parents: Mapping[str, Iterable[str]], seconds: Mapping[str, float]) -> dict[str, float]:
    """The longest remaining path from each model: its time plus the longest path among the
    models that take it as derived_base (models on a cycle count only their own time)."""
    children = dag.children_of(parents)
    out: dict[str, float] = {}
    for node in reversed(dag.order(parents)):
        out[node] = seconds[node] + max((out[c] for c in children[node] if c in out), default=0.0)
    for node in parents:
        out.setdefault(node, seconds[node])
    return out


def sources(definition: Path, data: Any) -> frozenset[str]:
    """The basefiles a definition reads (the files whose meshes its build converts); a
    derived_base reads its parent's output, which is converted already."""
    model = data.get("model") if isinstance(data, dict) else None
    inputs = model.get("input_models") if isinstance(model, dict) else None
    out = set()
    for entry in inputs.values() if isinstance(inputs, dict) else ():
        basefile = entry.get("basefile") if isinstance(entry, dict) else None
        if isinstance(basefile, str):
            out.add(basefile if "://" in basefile else str(resolved(definition.parent / basefile)))
    return frozenset(out)


def next_model(ready: Sequence[str], priority: Mapping[str, float],
               busy: Iterable[frozenset[str]], source: Mapping[str, frozenset[str]]) -> str:
    """The ready model to start: the highest priority among those sharing no source with a
    running model (`busy`: the running models' sources), else the highest priority; ties
    keep `ready`'s order."""
    taken = frozenset().union(*busy)
    ranked = sorted(ready, key=lambda n: -priority[n])  # stable: ties keep the order
    return next((n for n in ranked if not source.get(n, frozenset()) & taken), ranked[0])


def last_seconds(status: Mapping[str, Any], states: Mapping[str, Mapping[str, Any]]) -> dict[str, float]:
    """Each model's last known build time: its wall time in the last status.json, or the sum
    of the stage times its state kept; models without either are left out."""
    out: dict[str, float] = {}
    models = status.get("models") if isinstance(status.get("models"), dict) else {}
    for name, state in states.items():
        stages = state.get("stages") if isinstance(state.get("stages"), dict) else {}
        total = sum(s.get("seconds", 0) for s in stages.values() if isinstance(s, dict)
                    and isinstance(s.get("seconds", 0), int | float))
        if total > 0:
            out[name] = float(total)
    for name, record in models.items():
        wall = record.get("seconds") if isinstance(record, dict) else None
        if isinstance(wall, int | float) and not isinstance(wall, bool) and wall > 0:
            out[name] = float(wall)
    return out
