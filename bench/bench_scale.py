"""How compile time grows with the size of a model: a chain and a binary tree of N links
(boxes, no meshes), each export type compiled on its own, at 1,000 and 10,000 links.

Target (issue 19): linear, i.e. at most 12× the time from 1,000 to 10,000 links, and a
10,000-link model exporting urdf + sdf + smurf + mjcf in at most 8 s, cold.
Run: python bench/bench_scale.py [N N …]   (default: 1000 10000)
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXPORTS = ("urdf", "sdf", "smurf", "mjcf")


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


def compile_seconds(folder: Path, urdf: Path, exports: tuple[str, ...]) -> float:
    spec = folder / f"{'-'.join(exports)}.yml"
    spec.write_text(f"model:\n  robotname: r\n  modelname: r-model\n"
                    f"  input_models: {{r: {{basefile: '{urdf}'}}}}\n  assemble: {{model: r}}\n"
                    f"  export_config: [{', '.join(f'{{type: {e}}}' for e in exports)}]\n")
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o",
                           str(folder / f"out-{spec.stem}")], capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"compile failed: {done.stderr}")
    return seconds


def main(sizes: list[int]) -> None:
    cases = [(e,) for e in EXPORTS] + [EXPORTS]
    for shape in ("chain", "tree"):
        times: dict[tuple[int, tuple[str, ...]], float] = {}
        with tempfile.TemporaryDirectory() as tmp:
            for n in sizes:
                urdf = Path(tmp) / f"{shape}{n}.urdf"
                urdf.write_text(model(n, shape))
                for exports in cases:
                    times[n, exports] = compile_seconds(Path(tmp), urdf, exports)
        print(f"{shape}: seconds per compile (a process each, cold)")
        print("  exports                " + "".join(f"{n:>10}" for n in sizes)
              + (f"   growth {sizes[0]}→{sizes[-1]}" if len(sizes) > 1 else ""))
        for exports in cases:
            row = "".join(f"{times[n, exports]:10.2f}" for n in sizes)
            growth = times[sizes[-1], exports] / times[sizes[0], exports] if len(sizes) > 1 else 0
            print(f"  {'+'.join(exports):<23}{row}" + (f"   {growth:6.1f}×" if len(sizes) > 1 else ""))


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 10000])
