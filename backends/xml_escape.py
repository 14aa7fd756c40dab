"""XML escaping, written once: a string → the text of an element or the value of an attribute.

What xml.sax.saxutils.escape gives (with quotes and whitespace for attributes), without
importing saxutils: it imports urllib.request and http.client, which `mpc check` (it imports
the URDF writer) never uses. What it does not do: drop characters XML cannot hold.
"""

from __future__ import annotations

import re

_ATTRIBUTE_SPECIAL = re.compile('[&<>"\n\r\t]')


def text(value: str) -> str:
    """`value` as the text of an element: `&`, `<` and `>` escaped."""
    return value.replace("&", "&amp;").replace(">", "&gt;").replace("<", "&lt;")


def attribute(value: str) -> str:
    """`value` inside a double-quoted attribute: also `"`, and the whitespace that a parser
    would turn into spaces (newline, carriage return, tab) as character references."""
    if _ATTRIBUTE_SPECIAL.search(value) is None:  # most values (numbers, names): one scan
        return value
    return (text(value).replace('"', "&quot;").replace("\n", "&#10;").replace("\r", "&#13;")
            .replace("\t", "&#9;"))
