"""A `type: render` entry of export_config → ir.RenderExport, its values checked.

Pose names are checked when the pictures are drawn (backends/render.py): the poses exist only
once the ops have run.
"""

from __future__ import annotations

from typing import Any

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.ir.program import RENDER_BACKGROUNDS, RENDER_VIEWS, RenderExport

MAX_SIDE = 4096  # pixels: MuJoCo's offscreen buffer, and what a review page can show


def lower_render(entry: Any, sink: Sink, submodel: str = "") -> RenderExport | None:
    """The render export of `entry`, or None after an error (E0572–E0574)."""
    ok = True
    views: list[str] = []
    for i, view in enumerate(entry.views):
        span = entry.value_span("views", i) if isinstance(
            entry.data_at("views"), list) else entry.value_span("views")
        if view not in RENDER_VIEWS:
            sink.error(span, "E0572", f"render view '{view}' is none of {', '.join(RENDER_VIEWS)}"
                       f"{did_you_mean(view, set(RENDER_VIEWS))}")
            ok = False
        elif view in views:
            sink.error(span, "E0572", f"render view '{view}' is listed twice")
            ok = False
        views.append(view)
    if not views:
        sink.error(entry.value_span("views"), "E0572", "a render export needs at least one view")
        ok = False
    size = entry.size
    if len(size) != 2 or not all(isinstance(n, int) and 16 <= n <= MAX_SIDE for n in size):
        sink.error(entry.value_span("size"), "E0573", f"size {list(size)} is not [width, height] "
                   f"in pixels, each from 16 to {MAX_SIDE}")
        ok = False
    background = _colour(entry.background, entry, sink)
    if background is None:
        sink.error(entry.value_span("background"), "E0574", f"background {entry.background!r} is no "
                   f"colour: write one of {', '.join(RENDER_BACKGROUNDS)} or [r, g, b] with each from "
                   "0 to 1")
        ok = False
    poses = tuple(entry.poses)
    if "all" in poses and len(poses) > 1:
        sink.error(entry.value_span("poses"), "E0575", "poses: 'all' already means the zero pose and "
                   "every named pose; list names without it")
        ok = False
    if not ok:
        return None
    return RenderExport(span=entry.span, views=tuple(views), geometry=entry.geometry, poses=poses,
                        size=(size[0], size[1]), background=background, submodel=submodel)  # type: ignore[arg-type]


def _colour(value: object, entry: Any, sink: Sink) -> tuple[float, float, float] | None:
    """A named colour, or [r, g, b] (numbers or expressions, each from 0 to 1)."""
    if isinstance(value, str):
        return RENDER_BACKGROUNDS.get(value.lower())
    if not isinstance(value, list) or len(value) != 3:
        return None
    from mpc.compiler.expr import evaluate

    rgb = [evaluate(c, entry.value_span("background", i), sink, what="background")
           for i, c in enumerate(value)]
    if any(c is None or not 0 <= c <= 1 for c in rgb):
        return None
    return (rgb[0], rgb[1], rgb[2])  # type: ignore[return-value]
