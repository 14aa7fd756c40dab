"""A `kccd` export_config entry (AST) → ir.KccdExport: numbers evaluated, settings checked.

The names it gives (joints, links) are checked against the robot when it is written
(backends/kccd.py); lowering reads no model.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mpc.compiler.lower_context import LowerContext
from mpc.ir.program import Export, KccdExport

KCCD_SHAPES = ("box", "cylinder", "sphere", "convex")


def lower_kccd(low: LowerContext, entry: Any, written: dict[str, Export], submodel: str) -> list[Export]:
    """A `kccd` entry: its numbers evaluated and its per-link settings checked; the names
    it gives are checked against the robot when it is written (backends/kccd.py)."""
    parts = Path(entry.dirname).parts
    if not parts or Path(entry.dirname).is_absolute() or ".." in parts:
        low.sink.error(entry.value_span("dirname"), "E0521", f"kccd 'dirname' is a folder inside the "
                       f"output, got '{entry.dirname}'")
        return []
    target = f"{'submodels/' + submodel + '/' if submodel else ''}{entry.dirname}"
    if target in written:
        low.sink.error(entry.span, "E0503", f"two kccd exports would write {target}/",
                       notes=((written[target].span, "the other export"),))
        return []
    numbers = {key: low.num(entry, key, f"kccd {key}")
               for key in ("safety_distance", "report_up_to", "computation_budget")}
    budget = numbers["computation_budget"]
    faces, ratio = 0, 0.0
    reduce = low.num(entry, "reduce_meshes", "kccd reduce_meshes") if entry.reduce_meshes else 0.0
    if reduce is not None and 0 < reduce < 1:
        ratio = reduce
    elif reduce is not None and reduce >= 4 and float(reduce).is_integer():
        faces = int(reduce)
    elif reduce not in (None, 0):
        low.sink.error(entry.value_span("reduce_meshes"), "E0521", "kccd 'reduce_meshes' is the "
                       "fraction of each hull's faces to remove (between 0 and 1, as in Phobos) or a "
                       f"number of faces to keep (4 or more), got {reduce:g}")
    n_points: dict[str, int] = {}
    shapes: dict[str, str] = {}
    for link, settings in entry.edit_collisions.items():
        for key, value in settings.items():
            if key == "n_points" and isinstance(value, int) and value >= 1:
                n_points[link] = value
            elif key == "shape" and value in KCCD_SHAPES:
                shapes[link] = str(value)
            else:
                span = entry.value_span("edit_collisions", link, key)
                low.sink.error(span, "E0521", f"kccd edit_collisions of '{link}': '{key}: {value}' is "
                               "neither n_points (a whole number, 1 or more) nor shape "
                               f"({', '.join(KCCD_SHAPES)})")
    braking: tuple[float, ...] = ()
    if entry.braking_model is not None:
        b = entry.braking_model
        values = [low.num(b, key, f"braking_model {key}")
                  for key in ("linearFactor", "invDeceleration", "uncertainty", "latency")]
        braking = tuple(v if v is not None else 0.0 for v in values)
    written[target] = export = KccdExport(
        span=entry.span, dirname=entry.dirname, join_before_convexhull=entry.join_before_convexhull,
        remove_joints=tuple(entry.remove_joints), merge_additionally=tuple(entry.merge_additionally),
        keep_stls=entry.keep_stls, keep_urdf=entry.keep_urdf, reduce_faces=faces, reduce_ratio=ratio,
        n_points=n_points, shapes=shapes, braking_model=braking,
        simplify_swept_from=tuple(entry.simplify_swept_from),
        safety_distance=numbers["safety_distance"] or 0.0, report_up_to=numbers["report_up_to"] or 0.0,
        computation_budget=-1.0 if budget is None else budget,
        max_approximation_order=entry.max_approximation_order,
        no_collision_between={k: tuple(v) for k, v in entry.no_collision_between.items()},
        submodel=submodel)
    return [export]
