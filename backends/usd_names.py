"""Prim names of a USD export: each element's name made a valid USD identifier by
Tf.MakeValidIdentifier (every byte that is not a letter, a digit or '_' becomes '_', and so
does a leading digit) and unique among its siblings (`_1`, `_2`, … appended in the order the
elements come). The original name is kept on the prim as `mpc:name`."""

from __future__ import annotations

from collections.abc import Iterable

from mpc.backends.usd_pxr import Tf
from mpc.core.names import free_name


def unique_identifiers(names: Iterable[str], taken: Iterable[str] = ()) -> dict[str, str]:
    """Each name → its identifier, unique among them and not one of `taken`."""
    used = set(taken)
    out: dict[str, str] = {}
    for name in names:
        if name in out:
            continue
        new = free_name(Tf.MakeValidIdentifier(name), used)
        used.add(new)
        out[name] = new
    return out


def sibling_names(names: Iterable[str]) -> list[str]:
    """One identifier per item (a name given twice gets two), unique among them."""
    used: set[str] = set()
    out: list[str] = []
    for name in names:
        new = free_name(Tf.MakeValidIdentifier(name), used)
        used.add(new)
        out.append(new)
    return out
