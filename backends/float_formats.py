"""`float_fmt_dict`: printf formats for the numbers of chosen URDF attributes or SDF elements.

Without it (or for a key it does not name) mpc writes each number in its shortest exact
form (backends/xml.py `fmt_float`). With it, as in Phobos, a key names a URDF attribute
(`xyz`, `ixx`, `value`, …), an SDF element (`pose`, `mass`, `ixx`, …) or an MJCF attribute
(`pos`, `quat`, `diaginertia`, …; MuJoCo's compiler settings are not numbers of the robot), and `default`
every number the writer writes; each number of that value is written with the format
(`%.6f`: Phobos's style). A format that rounds to zero writes `0`, never `-0`; the
output stays byte-stable (the same model and formats give the same bytes). Names, file
paths and the opaque fragments copied from the input are never reformatted.
"""

from __future__ import annotations

from collections.abc import Mapping

from mpc.ir.float_format_keys import DEFAULT, MJCF_KEYS, SDF_KEYS, URDF_KEYS, bad_format

__all__ = ["DEFAULT", "MJCF_KEYS", "SDF_KEYS", "URDF_KEYS", "Formats", "bad_format"]


def _one(token: str, fmt: str) -> str:
    text = fmt % float(token)
    return text.lstrip("+ -") if float(text) == 0 else text


class Formats:
    """The formats of one export, applied to the value written for a key."""

    def __init__(self, formats: Mapping[str, str] | tuple[tuple[str, str], ...],
                 keys: frozenset[str]) -> None:
        self.formats, self.keys = dict(formats), keys

    def __call__(self, key: str, text: str | None) -> str | None:
        """`text` (numbers written by the writer) in the format given for `key`."""
        if text is None or key not in self.keys:
            return text
        fmt = self.formats.get(key, self.formats.get(DEFAULT))
        if fmt is None:
            return text
        return " ".join(_one(token, fmt) for token in text.split())
