"""The fence around cli/pydantic_plugins.py, the stand-in for pydantic's private plugin loader:
it replaces exactly what the installed pydantic takes from that module, and only the `mpc`
program installs it (a program that imports mpc's modules keeps pydantic's own)."""

from __future__ import annotations

import ast
import importlib.util
import inspect
import subprocess
import sys
from pathlib import Path

import pydantic

from mpc.cli import pydantic_plugins
from tests.conftest import definition, write

PLUGIN_PACKAGE = "pydantic.plugin"
LOADER = pydantic_plugins.PRIVATE.rsplit(".", 1)[1]  # "_loader"


def _uses_of_the_loader() -> tuple[set[str], list[str]]:
    """What pydantic's own modules take from the private loader: the names they import from it
    (or read off it as a module), and each place that uses it in another way."""
    root = Path(pydantic.__file__).parent
    names: set[str] = set()
    other: list[str] = []
    for file in sorted(root.rglob("*.py")):
        module = ".".join(("pydantic", *file.relative_to(root).with_suffix("").parts))
        if module.endswith(".__init__"):
            module = module.removesuffix(".__init__")
        if module == pydantic_plugins.PRIVATE:
            continue
        package = module if file.name == "__init__.py" else module.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(file.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                base = importlib.util.resolve_name("." * node.level + (node.module or ""), package) \
                    if node.level else node.module
                if base == pydantic_plugins.PRIVATE:
                    names.update(alias.name for alias in node.names)
                elif base == PLUGIN_PACKAGE and any(a.name == LOADER for a in node.names):
                    other.append(f"{module}: imports the module {LOADER}")
            elif isinstance(node, ast.Import):
                other += [f"{module}: import {a.name}" for a in node.names
                          if a.name == pydantic_plugins.PRIVATE]
            elif isinstance(node, ast.Attribute) and node.attr == LOADER:
                other.append(f"{module}:{node.lineno}: .{LOADER}")
    return names, other


def test_the_stand_in_replaces_all_that_the_installed_pydantic_takes_from_the_private_loader() -> None:
    names, other = _uses_of_the_loader()
    assert not other, f"pydantic {pydantic.VERSION} uses {pydantic_plugins.PRIVATE} otherwise: {other}"
    assert names == set(pydantic_plugins.REPLACED), (
        f"pydantic {pydantic.VERSION} takes {sorted(names)} from {pydantic_plugins.PRIVATE}; "
        f"cli/pydantic_plugins.py replaces {sorted(pydantic_plugins.REPLACED)}")


def test_the_private_get_plugins_is_still_called_with_nothing_and_gives_plugins() -> None:
    import pydantic.plugin._loader as real  # the real one: this test process is no `mpc`

    assert inspect.signature(real.get_plugins).parameters == {}
    assert inspect.signature(pydantic_plugins.REPLACED["get_plugins"]).parameters == {}
    root = Path(pydantic.__file__).parent
    calls = [node for file in root.rglob("*.py")
             for node in ast.walk(ast.parse(file.read_text(encoding="utf-8")))
             if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
             and node.func.id == "get_plugins"]
    assert calls and all(not c.args and not c.keywords for c in calls)
    assert list(pydantic_plugins.REPLACED["get_plugins"]()) == []


PROBE = """\
import sys
{before}
from mpc.compiler import front_end
from mpc.core.diagnostics import Sink
from mpc.compiler.options import Options
from pathlib import Path
sink = Sink()
assert front_end.load_program(Path(sys.argv[1]), sink, Options()) is not None, sink.diagnostics
loader = sys.modules.get("pydantic.plugin._loader")
print(getattr(loader, "__file__", None) is None, "importlib.metadata" in sys.modules)
"""


def _probe(tmp_path: Path, before: str) -> str:
    write(tmp_path / "arm.urdf", '<robot name="arm"><link name="base"/></robot>\n')
    path = write(tmp_path / "arm.yml", definition("arm.urdf"))
    probe = write(tmp_path / "probe.py", PROBE.format(before=before))
    done = subprocess.run([sys.executable, str(probe), str(path)], capture_output=True, text=True,
                          check=False, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_only_the_mpc_program_installs_the_stand_in(tmp_path: Path) -> None:
    # A program using mpc's modules validates a definition with pydantic's own loader.
    assert _probe(tmp_path, "") == "False True"
    # `mpc` (cli/main.py main) puts the stand-in first: no plugins, importlib.metadata not read.
    mpc_check = "from mpc.cli.main import main\nassert main(['check', sys.argv[1]]) == 0"
    assert _probe(tmp_path, mpc_check) == "True False"
