"""A name not yet taken: `name`, else `name_1`, `name_2`, … (from `first`), as the writers and
readers that make names (MJCF assets, USD prims, an MJCF input's chain links) number them."""

from __future__ import annotations

from collections.abc import Container


def free_name(name: str, taken: Container[str], first: int = 1) -> str:
    """`name` if it is not in `taken`, else `name_<n>` for the first n ≥ `first` that is not."""
    out, n = name, first
    while out in taken:
        out, n = f"{name}_{n}", n + 1
    return out
