"""One change between two models, as the diff reports it (checks/diff_models.py)."""

from __future__ import annotations

from typing import Any

from mpc.core.record import record


@record
class Change:
    """element: what changed (link, joint, collision, visual, material, motor, sensor, pose,
    submechanism, annotation, robot); name: its name in the new model (in the old one when
    it was removed); aspect: which of its properties (added, removed, renamed, mass, limit…);
    old, new: the values (JSON-able, None for none); text: the change in words."""

    element: str
    name: str
    aspect: str
    old: Any
    new: Any
    text: str

    def as_json(self) -> dict[str, Any]:
        return {"element": self.element, "name": self.name, "aspect": self.aspect, "old": self.old,
                "new": self.new, "text": self.text}
