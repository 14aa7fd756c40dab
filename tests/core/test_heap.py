"""A build's process keeps what it frees (core/heap.py `keep_freed`): a block freed and allocated
again is not mapped anew, page by page; other commands keep the C library's defaults."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

# Allocates and fills 8 MiB, frees it, does it again, and prints the page faults of the second.
_REFILL = textwrap.dedent("""
    import resource, sys
    from mpc.core import heap
    if sys.argv[1] == "keep":
        heap.keep_freed()
    def faults():
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    block = bytearray(8 << 20)
    del block
    before = faults()
    block = bytearray(8 << 20)
    print(faults() - before)
""")


def _refill_faults(mode: str) -> int:
    done = subprocess.run([sys.executable, "-c", _REFILL, mode], capture_output=True, text=True, check=True)
    return int(done.stdout)


def test_a_block_freed_is_reused_without_page_faults_once_freed_memory_is_kept() -> None:
    assert _refill_faults("keep") < 64  # the 2,048 pages were the process's already
    assert _refill_faults("default") > 1500  # glibc unmapped them: each is mapped again at its first touch


# Runs `mpc ARGS…` as the program does, and says whether it asked to keep freed memory.
_PROGRAM = textwrap.dedent("""
    import sys
    from mpc.core import heap
    keep = heap.keep_freed
    def noted():
        print("kept", file=sys.stderr)
        keep()
    heap.keep_freed = noted
    sys.argv = ["mpc", *sys.argv[1:]]
    from mpc.cli.main import program
    program()
""")


def test_compile_keeps_freed_memory_and_check_does_not(tmp_path: Path) -> None:
    (tmp_path / "robot.urdf").write_text('<robot name="r"><link name="base"/></robot>\n')
    (tmp_path / "robot.yml").write_text(textwrap.dedent("""\
        model:
          robotname: r
          modelname: r
          input_models: {r: {basefile: robot.urdf}}
          assemble: {model: r}
          export_config: [{type: urdf}]
    """))

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-c", _PROGRAM, *args], capture_output=True, text=True,
                              cwd=tmp_path, env={**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")})

    compiled = run("compile", "robot.yml", "-o", "out")
    assert compiled.returncode == 0, compiled.stderr
    assert compiled.stderr.splitlines()[0] == "kept"
    assert (tmp_path / "out/urdf/r.urdf").is_file()
    checked = run("check", "robot.yml")
    assert checked.returncode == 0, checked.stderr
    assert "kept" not in checked.stderr.splitlines()

