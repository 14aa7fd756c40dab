"""Plain YAML data → the text PyYAML's block-style dumper writes for it, about 30× faster.

`block_yaml` writes mappings (sorted keys), sequences and scalars the way
`yaml.dump(data, default_flow_style=False, sort_keys=True, width=1 << 16)` does, for the
data where that is simple: every key and string a plain scalar of a few safe characters
(names, types, file paths), every float written by `float_text`. It returns None for
anything else (quoting, escapes, long or non-ASCII text), and the caller dumps that with
PyYAML; it does not quote, escape or wrap.
"""

from __future__ import annotations

import math
import re
from typing import Any

from mpc.backends.xml import fmt_float

# Strings PyYAML writes plain: a letter or '_' first (after any '../', a relative path's), then
# names, paths and numbers, single spaces inside; no indicator, no ': ' or ' #', nothing YAML
# 1.1 reads as another type.
_PLAIN_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_./-]*(?: [A-Za-z0-9_./-]+)*")
_PLAIN = re.compile(r"(?:\.\./)*[A-Za-z_](?:[A-Za-z0-9_./-]|:(?=[^ ]))*(?: (?:[A-Za-z0-9_./-]|:(?=[^ ]))+)*")
_NOT_STR = frozenset(w for word in ("yes", "no", "true", "false", "on", "off", "null", "y", "n")
                     for w in (word, word.capitalize(), word.upper()))
_LONGEST_KEY, _LONGEST_TEXT = 60, 1000


def float_text(x: float) -> str:
    """The URDF writer's float text, made a YAML 1.1 float too (`2` → `2.0`, `1e-05` → `1.0e-05`)."""
    if math.isnan(x):
        return ".nan"
    if math.isinf(x):
        return ".inf" if x > 0 else "-.inf"
    text = fmt_float(x)
    mantissa, e, exponent = text.partition("e")
    return text if "." in mantissa else f"{mantissa}.0{e}{exponent}"


class _Unlike(Exception):
    """The data holds something this writer leaves to PyYAML."""


def _text(value: str, longest: int, plain: re.Pattern[str] = _PLAIN) -> str:
    if len(value) > longest or value in _NOT_STR or not plain.fullmatch(value):
        raise _Unlike
    return value


def _scalar(value: Any) -> str:
    if value is None:
        return "null"
    if value is True:
        return "true"
    if value is False:
        return "false"
    if type(value) is int:
        return str(value)
    if type(value) is float:
        return float_text(value)
    if type(value) is str:
        return _text(value, _LONGEST_TEXT) if value else "''"
    if value == {}:
        return "{}"
    if value == []:
        return "[]"
    raise _Unlike


def _mapping(data: dict[str, Any], indent: str, out: list[str]) -> None:
    for key in sorted(data):
        if type(key) is not str:
            raise _Unlike
        value = data[key]
        head = f"{indent}{_text(key, _LONGEST_KEY, _PLAIN_KEY)}:"
        if type(value) is dict and value:
            out.append(head)
            _mapping(value, indent + "  ", out)
        elif type(value) is list and value:
            out.append(head)
            _sequence(value, indent, out)  # PyYAML does not indent a sequence in a mapping
        else:
            out.append(f"{head} {_scalar(value)}")


def _sequence(data: list[Any], indent: str, out: list[str]) -> None:
    inner = indent + "  "
    for value in data:
        if (type(value) is dict or type(value) is list) and value:
            first = len(out)
            (_mapping if type(value) is dict else _sequence)(value, inner, out)
            out[first] = f"{indent}- {out[first][len(inner):]}"  # the first line follows the dash
        else:
            out.append(f"{indent}- {_scalar(value)}")


def block_yaml(data: Any) -> str | None:
    """PyYAML's block-style text of `data` (a non-empty mapping of plain data), or None."""
    if type(data) is not dict or not data:
        return None
    out: list[str] = []
    try:
        _mapping(data, "", out)
    except _Unlike:
        return None
    return "\n".join(out) + "\n"
