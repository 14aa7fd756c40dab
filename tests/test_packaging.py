"""mpc's folders install as `mpc.*`, and every tool follows them.

The floors stay at the repository's root (core/, ir/, ...); setup.py derives the packages from
the folders, so that the wheel holds every one, a new subpackage included; in a checkout set up
by scripts/setup.sh, basedpyright (Pylance's engine) and jedi resolve `mpc.*` to the checkout's
files; and scripts/typecheck.sh holds a baseline that may only shrink.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import jedi
import pytest

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent
NOT_MPC = ("tests", "bench")  # folders with Python files that are not part of mpc


def _tracked_copy(to: Path) -> Path:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for name in files.decode().split("\0"):
        if name and (ROOT / name).is_file():
            (to / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, to / name)
    return to


def _build_wheel(src: Path, out: Path) -> Path:
    env = {**os.environ, "UV_SYSTEM_CERTS": "1", "UV_PYTHON_DOWNLOADS": "never"}
    done = subprocess.run([str(BIN / "uv"), "build", "--wheel", "--quiet", "--out-dir", str(out), str(src)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    (wheel,) = out.glob("*.whl")
    return wheel


def test_the_wheel_holds_every_folder_with_python_files_a_new_subpackage_included(tmp_path: Path) -> None:
    src = _tracked_copy(tmp_path / "src")
    (src / "ir/ops/newly").mkdir()
    (src / "ir/ops/newly/__init__.py").write_text('"""A subpackage no list names."""\n')
    (src / "compiler/plain").mkdir()
    (src / "compiler/plain/module.py").write_text("X = 1\n")  # a folder without __init__.py
    expected = {
        f"mpc/{path.relative_to(src).as_posix()}"
        for path in src.rglob("*")
        if path.suffix in (".py", ".lark") and path.relative_to(src).parts[0] not in NOT_MPC
        and len(path.relative_to(src).parts) > 1
    }
    with zipfile.ZipFile(_build_wheel(src, tmp_path / "dist")) as wheel:
        code = {name for name in wheel.namelist() if not name.split("/")[0].endswith(".dist-info")}
    assert code == expected
    assert {"mpc/ir/ops/newly/__init__.py", "mpc/compiler/plain/module.py", "mpc/grammar/ir.lark"} <= code


def test_jedi_follows_an_mpc_import_into_the_checkout() -> None:
    source = "from mpc.ir import Robot\n"
    script = jedi.Script(source, path=ROOT / "probe.py", project=jedi.Project(ROOT),
                         environment=jedi.create_environment(sys.prefix, safe=False))
    (found,) = script.goto(1, len(source) - 2, follow_imports=True)
    assert found.module_path is not None
    assert Path(found.module_path).resolve() == ROOT / "ir/robot.py"
    assert found.type == "class" and found.name == "Robot"


def test_basedpyright_resolves_every_mpc_package_to_the_checkout(tmp_path: Path) -> None:
    tracked = subprocess.run(["git", "ls-files", "*.py"], cwd=ROOT, capture_output=True, text=True,
                             check=True).stdout.split()
    packages = sorted({".".join(("mpc", *Path(name).parent.parts)) for name in tracked
                       if "/" in name and name.split("/")[0] not in NOT_MPC})
    probe = tmp_path / "probe.py"
    probe.write_text("".join(f"import {p}\n" for p in packages)
                     + "from mpc.ir import Robot\nreveal_type(Robot)\n")
    done = subprocess.run([str(BIN / "basedpyright"), "--outputjson", "-p", str(ROOT), str(probe)],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    found = json.loads(done.stdout)["generalDiagnostics"]
    unresolved = [d["message"] for d in found if d.get("rule") == "reportMissingImports"]
    assert len(packages) >= 13 and unresolved == []
    revealed = [d["message"] for d in found if d["severity"] == "information"]
    assert revealed == ['Type of "Robot" is "type[Robot]"']


@pytest.mark.long  # seven runs of basedpyright
def test_the_type_check_fails_on_a_new_error_and_on_an_error_fixed_but_still_listed(tmp_path: Path) -> None:
    (tmp_path / "scripts").mkdir()
    shutil.copy(ROOT / "scripts/typecheck.sh", tmp_path / "scripts")
    (tmp_path / ".venv").symlink_to(Path(sys.prefix))
    (tmp_path / "pyproject.toml").write_text(textwrap.dedent("""\
        [tool.basedpyright]
        include = ["pkg"]
        venvPath = "."
        venv = ".venv"
        typeCheckingMode = "standard"
        """))
    module = tmp_path / "pkg/module.py"
    module.parent.mkdir()
    module.write_text('a: int = "one"\n')

    def check(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(["bash", "scripts/typecheck.sh", *args], cwd=tmp_path, capture_output=True,
                              text=True, timeout=300)

    (tmp_path / ".basedpyright").mkdir()
    (tmp_path / ".basedpyright/baseline.json").write_text('{"files": {}}')
    assert check().returncode == 1  # an error the baseline does not list
    assert check("--writebaseline").returncode == 0
    assert check().returncode == 0  # the same error, listed
    module.write_text('a: int = "one"\nb: str = 2\n')
    assert check().returncode == 1  # one more
    module.write_text("a: int = 1\n")
    fixed = check()
    assert fixed.returncode == 1  # listed but gone: the baseline shrinks, to be committed
    assert "commit the shrunk .basedpyright/baseline.json" in fixed.stderr
    assert check().returncode == 0
