"""`mpc` (the program, not the library) gives pydantic no plugins, and so starts faster.

pydantic asks the installed packages for plugins (entry points) when it builds its first
validator: `pydantic.plugin._schema_validator` imports `get_plugins` from the private module
`pydantic.plugin._loader`, whose import brings in importlib.metadata, a tenth of a cold
`mpc check`. The definition language takes no plugin, and another package's must not change
how mpc validates; so the program puts a finder first on `sys.meta_path` that answers the
import of that module with a stand-in whose `get_plugins()` gives none.

A hack on a private module, fenced: only `cli/main.py` installs it (importing mpc's modules
from another program leaves pydantic as it is), pyproject.toml keeps pydantic below 3, and
tests/cli/test_pydantic_plugins.py fails when the installed pydantic uses the private module
for anything but `get_plugins()`.
"""

from __future__ import annotations

import sys
import types
from collections.abc import Iterable
from importlib.machinery import ModuleSpec
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from importlib.abc import Loader

PRIVATE = "pydantic.plugin._loader"


def _get_plugins() -> Iterable[object]:
    return ()


# What the stand-in module holds: pydantic's names from the private module, each replaced.
REPLACED = {"get_plugins": _get_plugins}


class _StandIn:
    """Finds and makes the stand-in when pydantic imports its loader (a finder first on
    `sys.meta_path`): a run that never validates a definition imports nothing of pydantic.
    The finder and loader protocols without importlib.abc's classes, whose import (through
    importlib.resources) every `mpc` process would pay."""

    def find_spec(self, name: str, path: object = None, target: object = None) -> ModuleSpec | None:
        return ModuleSpec(name, cast("Loader", self), origin=None) if name == PRIVATE else None

    def create_module(self, spec: ModuleSpec) -> None:
        return None  # a plain module

    def exec_module(self, module: types.ModuleType) -> None:
        module.__doc__ = "mpc: no pydantic plugins (cli/pydantic_plugins.py)"
        module.__dict__.update(REPLACED)


def install() -> None:
    """Give pydantic no plugins; nothing when pydantic's own loader is imported already."""
    if PRIVATE not in sys.modules and not any(isinstance(f, _StandIn) for f in sys.meta_path):
        sys.meta_path.insert(0, _StandIn())
