"""The floor of a cold build, and mpc's cold build over it (issue 34).

The floor is what any compiler of the definition must do: start Python with numpy and lxml,
read and decode each distinct source mesh once (a binary STL with `numpy.frombuffer`, an
ASCII STL with numpy's float parser, a DAE parsed by lxml with `huge_tree` and its number
arrays by numpy), and write each output file once (as many bytes as mpc writes, into a new
folder: a cold build makes its files, it does not overwrite them). It runs as a program of its
own, in a fresh process, beside `mpc compile` with an empty cache, in turns (floor, mpc, floor,
mpc, …): the ratio of each pair, and their median, hold when the machine's speed drifts.

Each pair runs in folders of its own (the floor's output; mpc's cache and output), and nothing
is deleted until the end. Until 2026-11-28 the floor overwrote the files of its first run,
and the cache and output of the last build were deleted just before each cold build. On this
development machine (ext4 mounted with `discard`, in a VM) a file made soon after many were
deleted can cost 0.8 ms instead of 0.03 ms: mpc's 88 output meshes took 68-81 ms there against
24-27 ms in a folder of their own, while the floor, overwriting, made no file at all
(bench/README.md, 2026-11-28).

The warm `--force` rebuild (the mesh cache filled, the kept build read for its program only)
is timed too: right after each cold build, and in a row of its own once the cache has settled
(two seconds after the last build: what mpc remembers of a file by its status is kept for
other processes only when the file is older than that, core/cache.py), as a rebuild minutes
after the last one finds it. Each figure is printed beside its goal.

Run: python bench/bench_floor.py [DEFINITION] [--runs N]
(no DEFINITION: the 88-link assembly of bench_assembly.py, TALOS + UR5 + a mirrored arm)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FLOOR = r'''
import json, os, sys
import numpy as np
from lxml import etree

plan = json.loads(open(sys.argv[1]).read())
record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
for path in plan["sources"]:
    data = open(path, "rb").read()
    if path.lower().endswith(".stl"):
        count = int(np.frombuffer(data, "<u4", 1, 80)[0]) if len(data) >= 84 else -1
        if len(data) == 84 + 50 * count:
            np.frombuffer(data, record, offset=84)["v"].astype(np.float64)
        else:
            text = data.decode(errors="replace").lower()
            np.fromstring(" ".join(c[: c.find("\n")] for c in text.split("vertex")[1:]), sep=" ")
    elif path.lower().endswith(".dae"):
        root = etree.fromstring(data, etree.XMLParser(huge_tree=True, resolve_entities=False))
        for element in root.iter("{*}float_array"):
            np.fromstring(element.text or "", dtype=np.float32, sep=" ")
        for element in root.iter("{*}p", "{*}vcount"):
            np.fromstring(element.text or "", dtype=np.int64, sep=" ")
out = sys.argv[2]
for folder in sorted({path.rpartition("/")[0] for path, _ in plan["outputs"]}):
    os.makedirs(f"{out}/{folder}", exist_ok=True)
for path, size in plan["outputs"]:
    with open(f"{out}/{path}", "wb") as f:
        f.write(bytes(size))
'''


def assembly(folder: Path) -> Path:
    """The definition of bench_assembly.py, written into `folder`."""
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_assembly import DEFINITION

    from mpc.core.packages import PackageResolver

    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "pip install example-robot-data"
    spec = folder / "assembly.yml"
    spec.write_text(DEFINITION.format(talos=erd / "robots/talos_data/robots/talos_full_v2.urdf",
                                      ur5=erd / "robots/ur_description/urdf/ur5_robot.urdf"))
    return spec


def plan(spec: Path, tmp: Path) -> dict[str, list]:
    """The distinct source meshes of the definition and the files of its build (path, size)."""
    from mpc.backends.meshes import mesh_uses
    from mpc.compiler.driver import Options, compile_model
    from mpc.core.diagnostics import Sink

    os.environ["MPC_CACHE_DIR"] = str(tmp / "plan-cache")
    result = compile_model(spec, Sink(), Options(out=tmp / "plan-out"))
    assert result.out is not None and result.robot is not None, "the definition does not compile"
    sources = sorted({str(u.mesh.source.path) for u in mesh_uses(result.robot) if u.mesh.source.path})
    outputs = [(p.relative_to(result.out).as_posix(), p.stat().st_size)
               for p in sorted(result.out.rglob("*")) if p.is_file()]
    return {"sources": sources, "outputs": outputs}


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process and its children) of one run."""
    t0 = time.perf_counter()
    child = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"failed: {' '.join(command)}")
    return wall, usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("definition", nargs="?", type=Path)
    parser.add_argument("--runs", type=int, default=7, help="pairs of runs (default 7)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp_:
        tmp = Path(tmp_)
        spec = args.definition.resolve() if args.definition else assembly(tmp)
        work = plan(spec, tmp)
        (tmp / "plan.json").write_text(json.dumps(work))
        (tmp / "floor.py").write_text(FLOOR)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}

        def floor_run(run: str) -> tuple[float, float]:
            return timed([sys.executable, str(tmp / "floor.py"), str(tmp / "plan.json"),
                          str(tmp / run / "floor-out")], env)

        def mpc_run(run: str, *flags: str) -> tuple[float, float]:
            return timed([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o",
                          str(tmp / run / "out"), *flags], {**env, "MPC_CACHE_DIR": str(tmp / run / "cache")})

        floor_run("warm-up")  # bytecode compiled, files in the page cache
        mpc_run("warm-up")
        floors, colds, warms = [], [], []
        for run in map(str, range(args.runs)):  # a folder each: nothing is deleted before a run
            floors.append(floor_run(run))
            colds.append(mpc_run(run))
            warms.append(mpc_run(run, "--force"))
        time.sleep(2.5)
        last = str(args.runs - 1)
        mpc_run(last, "--force")  # what a rebuild remembers of the files, remembered
        settled = [mpc_run(last, "--force") for _ in range(args.runs)]
        ratios = [c[0] / f[0] for f, c in zip(floors, colds, strict=True)]
        cpu_ratios = [c[1] / f[1] for f, c in zip(floors, colds, strict=True)]
        floor, cold, warm = (statistics.median(r[0] for r in runs) for runs in (floors, colds, warms))
        load = " ".join(f"{x:.2f}" for x in os.getloadavg())
        size = sum(s for _, s in work["outputs"]) / 1e6
        print(f"{spec.name}: {len(work['sources'])} distinct source meshes, {len(work['outputs'])} output "
              f"files ({size:.1f} MB); {args.runs} pairs; load average {load}")
        print(f"floor: {floor:.3f} s (CPU {statistics.median(r[1] for r in floors):.3f} s)")
        print(f"mpc cold: {cold:.3f} s (CPU {statistics.median(r[1] for r in colds):.3f} s)")
        print(f"cold / floor: {statistics.median(ratios):.2f}× (pairs {min(ratios):.2f}–{max(ratios):.2f}; "
              f"CPU {statistics.median(cpu_ratios):.2f}×); goal ≤ 2.0×")
        warm_cpu = statistics.median(r[1] for r in warms)
        print(f"warm --force right after the cold build: {warm:.3f} s (CPU {warm_cpu:.3f} s)")
        print(f"warm --force, the cache settled: {statistics.median(r[0] for r in settled):.3f} s "
              f"(CPU {statistics.median(r[1] for r in settled):.3f} s); goal ≤ 0.30 s")


if __name__ == "__main__":
    main()
