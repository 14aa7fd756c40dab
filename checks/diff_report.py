"""A model diff (checks/diff_models.py) → text for people (`human`), for a merge request
(`markdown`, with the pictures) and for programs (`json`). Byte-stable: the changes in the
diff's order, numbers in fixed formats."""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence

from mpc.checks.diff_models import Diff
from mpc.ir.program import Tolerances

_QUOTED = re.compile(r"'([^'\n]*)'")


def code_spans(text: str) -> str:
    """Names quoted 'so' in the text → `so` (Markdown code)."""
    return _QUOTED.sub(r"`\1`", text)


def tolerances_text(tol: Tolerances) -> str:
    return (f"mass {tol.mass:g} kg, distance {tol.distance:g} m, angle {tol.rad:g} rad, "
            f"other {tol.default:g}")


def summary(d: Diff) -> str:
    """`3 changes` or `no changes`."""
    n = len(d.changes)
    return f"{n} change{'s' * (n != 1)}" if n else "no changes"


def human(d: Diff, old: str, new: str, tol: Tolerances) -> str:
    lines = [f"{old} → {new}: {summary(d)} beyond the tolerances ({tolerances_text(tol)})"]
    lines += [f"  {c.text}" for c in d.changes]
    return "\n".join(lines) + "\n"


def markdown(d: Diff, old: str, new: str, tol: Tolerances,
             pictures: Mapping[str, Sequence[str]] | None = None, title: str = "Model diff") -> str:
    """The diff as Markdown; pictures: {view: the paths of its old, new and overlay pictures},
    relative to where the Markdown is read."""
    lines = [f"## {title}: `{old}` → `{new}`", "",
             f"**{summary(d)}** beyond the tolerances ({tolerances_text(tol)}).", ""]
    lines += [f"- {code_spans(c.text)}" for c in d.changes]
    if d.changes:
        lines.append("")
    if pictures:
        lines += ["| view | old | new | overlay |", "|---|---|---|---|"]
        for view, paths in pictures.items():
            cells = " | ".join(f"![{view} {side}]({p})" for side, p in zip(
                ("old", "new", "overlay"), paths, strict=True))
            lines.append(f"| {view} | {cells} |")
        lines.append("")
    return "\n".join(lines)


def as_json(d: Diff, old: str, new: str, tol: Tolerances, pictures: Sequence[str] = ()) -> str:
    data = {"old": old, "new": new, "changed": d.changed,
            "tolerances": {"mass": tol.mass, "distance": tol.distance, "rad": tol.rad,
                           "default": tol.default},
            "changes": [c.as_json() for c in d.changes], "pictures": list(pictures)}
    return json.dumps(data, indent=2, ensure_ascii=False) + "\n"
