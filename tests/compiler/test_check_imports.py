"""`mpc check` imports only what it uses (issue 3: it must start fast); the IR text still knows every op."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from mpc.ir import ops
from tests.conftest import ERD, definition, write

ROOT = Path(__file__).resolve().parents[2]
# Modules that checking the bundled example (one input, no edits) has no use for.
UNUSED = ("mpc.ir.ops.annotate", "mpc.ir.ops.frames", "mpc.ir.ops.joints", "mpc.ir.ops.meshes",
          "mpc.ir.extras", "mpc.backends.meshes", "mpc.deploy.forges", "urllib.request", "json")


def _check_and_list(path: Path, modules: tuple[str, ...]) -> str:
    code = ("import sys\nfrom mpc.cli.main import main\nstatus = main(['check', sys.argv[1]])\n"
            f"print(status, sorted(m for m in {modules!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, check=True)
    return done.stdout


def test_check_of_the_example_imports_no_op_it_does_not_use() -> None:
    assert _check_and_list(ROOT / "examples/talos.yml", UNUSED) == "0 []\n"


def test_check_imports_the_ops_a_definition_uses(tmp_path: Path) -> None:
    text = definition(ERD / "ur_description/urdf/ur5_robot.urdf") + (
        "  frames:\n    tool:\n      parent: tool0\n      xyz: [0, 0, 0.1]\n")
    write(tmp_path / "m.yml", text)
    assert _check_and_list(tmp_path / "m.yml", ("mpc.ir.ops.frames", "mpc.ir.ops.joints")) == \
        "0 ['mpc.ir.ops.frames']\n"


def test_the_ir_text_knows_every_op_in_a_fresh_process() -> None:
    """The printer and parser import every op module, though `mpc check` imports few."""
    code = "from mpc.ir.text_types import registry\nprint(' '.join(sorted(registry().ops)))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    every = sorted(getattr(ops, name).kind for names in ops.CATALOGUE.values() for name in names)
    assert done.stdout.split() == every
