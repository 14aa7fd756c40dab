"""How compile time and memory grow with the size of a model: a chain and a binary tree of
N links (boxes, no meshes), each export type compiled on its own, then urdf + sdf + smurf +
mjcf together, at 1,000 and 10,000 links; a process each (cold), its wall time and peak
resident memory.

Targets (issue 19): linear, i.e. at most 12× the time from 1,000 to 10,000 links; a
10,000-link model exporting urdf + sdf + smurf + mjcf in at most 8 s, cold; at most 1 GiB.
MuJoCo reads no bodies nested deeper than 496, so a chain that long gets E0695 for its MJCF
(marked `E0695`: the time is the time to that answer, the other exports being done).
Run: python bench/bench_scale.py [N N …]   (default: 1000 10000)
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXPORTS = ("urdf", "sdf", "smurf", "mjcf")
SEPARATE = (*EXPORTS, "joint_limits")


def model(n: int, shape: str) -> str:
    """A URDF of `n` box links: each link's parent is the previous one (chain) or link (i-1)//2 (tree)."""
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    box = '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
    out = ['<?xml version="1.0"?>', f'<robot name="{shape}">']
    out += [f'<link name="l{i}">{inertial}{box}</link>' for i in range(n)]
    for i in range(1, n):
        parent = i - 1 if shape == "chain" else (i - 1) // 2
        out.append(f'<joint name="j{i}" type="revolute"><parent link="l{parent}"/><child link="l{i}"/>'
                   '<origin xyz="0 0 0.1" rpy="0 0.01 0"/><axis xyz="0 1 0"/>'
                   '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return "\n".join([*out, "</robot>", ""])


def compile_once(folder: Path, urdf: Path, exports: tuple[str, ...]) -> tuple[float, int, str]:
    """Wall seconds, peak resident memory (bytes) and the error code it answered with ('' when
    it succeeded) of one `mpc compile`."""
    spec = folder / f"{'-'.join(exports)}.yml"
    spec.write_text(f"model:\n  robotname: r\n  modelname: r-model\n"
                    f"  input_models: {{r: {{basefile: '{urdf}'}}}}\n  assemble: {{model: r}}\n"
                    f"  export_config: [{', '.join(f'{{type: {e}}}' for e in exports)}]\n")
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o",
                             str(folder / f"out-{spec.stem}")], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    stderr = proc.stderr.read() if proc.stderr else ""
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    errors = set(re.findall(r"error\[(E\d+)\]", stderr))
    if code != 0 and errors != {"E0695"}:
        raise SystemExit(f"compile failed: {stderr}")
    return seconds, usage.ru_maxrss * 1024, "E0695" if code else ""


def main(sizes: list[int]) -> None:
    cases = [(e,) for e in SEPARATE] + [EXPORTS]
    print(f"load average at the start: {os.getloadavg()[0]:.1f}")
    for shape in ("chain", "tree"):
        runs: dict[tuple[int, tuple[str, ...]], tuple[float, int, str]] = {}
        with tempfile.TemporaryDirectory() as tmp:
            for n in sizes:
                urdf = Path(tmp) / f"{shape}{n}.urdf"
                urdf.write_text(model(n, shape))
                for exports in cases:
                    runs[n, exports] = compile_once(Path(tmp), urdf, exports)
        print(f"{shape}: seconds (peak MiB) per compile, a process each, cold")
        print("  exports                 " + "".join(f"{n:>16}" for n in sizes)
              + (f"   growth {sizes[0]}→{sizes[-1]}" if len(sizes) > 1 else ""))
        for exports in cases:
            cells = "".join(f"{runs[n, exports][0]:8.2f} ({runs[n, exports][1] / 2**20:4.0f})"
                            + (" " + runs[n, exports][2] if runs[n, exports][2] else "")
                            for n in sizes)
            growth = runs[sizes[-1], exports][0] / runs[sizes[0], exports][0] if len(sizes) > 1 else 0
            print(f"  {'+'.join(exports):<24}{cells}" + (f"   {growth:6.1f}×" if len(sizes) > 1 else ""))
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 10000])
