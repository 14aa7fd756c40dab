"""The op catalogue (ir/ops/__init__.py CATALOGUE) is the one list of the ops: the lazy names of
`mpc.ir.ops`, `import_all`, `__all__` and the IR text's registry derive from it. A new op is
its class in an op module and its name in the catalogue; these tests fail when the one is
there without the other, or when the imports static tools read differ from the catalogue.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

from mpc.ir import ops
from mpc.ir.ops import CATALOGUE, OPS, Op, import_all
from mpc.ir.text_types import registry

INIT = Path(ops.__file__)


def _defined_ops(module: str) -> list[str]:
    """The op classes an op module defines, in the order they are written."""
    mod = importlib.import_module(f"mpc.ir.ops.{module}")
    return [name for name, value in vars(mod).items()
            if inspect.isclass(value) and issubclass(value, Op) and value.__module__ == mod.__name__]


def _static_imports() -> dict[str, list[str]]:
    """The op modules and names ir/ops/__init__.py imports under TYPE_CHECKING."""
    tree = ast.parse(INIT.read_text())
    block = next(node for node in tree.body if isinstance(node, ast.If)
                 and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING")
    found: dict[str, list[str]] = {}
    for node in block.body:
        assert isinstance(node, ast.ImportFrom) and node.module is not None
        found.setdefault(node.module.rsplit(".", 1)[-1], []).extend(a.name for a in node.names)
    return found


def test_every_op_module_lists_exactly_the_ops_it_defines() -> None:
    modules = sorted(p.stem for p in INIT.parent.glob("*.py") if p.stem not in ("__init__", "base"))
    assert sorted(CATALOGUE) == modules
    assert {m: sorted(_defined_ops(m)) for m in modules} == {m: sorted(CATALOGUE[m]) for m in modules}


def test_the_imports_for_static_tools_are_the_catalogue() -> None:
    assert _static_imports() == {m: list(names) for m, names in CATALOGUE.items()}


def test_the_registered_ops_and_the_ir_text_derive_from_the_catalogue() -> None:
    kinds = {getattr(ops, name).kind for names in CATALOGUE.values() for name in names}
    assert set(import_all()) == kinds == set(registry().ops)
    assert set(ops.__all__) >= {name for names in CATALOGUE.values() for name in names}
    assert {cls.__name__ for cls in OPS.values()} == {n for names in CATALOGUE.values() for n in names}
