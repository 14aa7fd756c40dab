"""The 88-link assembly of issue 19, cold and warm: time, peak memory and a split by stage.

TALOS (talos_full_v2) with a UR5 (prefixed `ur5_`) and a mirrored copy of TALOS's left arm,
both attached to the torso, exporting urdf, sdf, smurf and joint_limits; written from
example-robot-data into a temporary folder. Cold: an empty MPC_CACHE_DIR; warm: the same
build again on the filled cache (it writes the outputs of the kept build, compiler/
build_cache.py); edited: the definition changed by a comment, built on the same cache (the
front end and the ops run, the meshes come from the cache). The output folder is removed
before each build. Each is `mpc compile` in a fresh process, run several
times; the figures are medians. Peak memory is the largest RSS of a build process (and its
mesh workers). A first build, not counted, compiles Python's bytecode. Stages come from
MPC_PROFILE (core/profile.py); "startup" is the rest of the process's time (the interpreter
and imports). Figures on a loaded machine: compare the CPU times.

Run: python bench/bench_assembly.py [--runs N]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpc.core.packages import PackageResolver

DEFINITION = """model:
  robotname: talos_assembly
  modelname: talos-assembly
  input_models:
    talos: {{basefile: "{talos}"}}
    ur5: {{basefile: "{ur5}"}}
  assemble:
    model: talos
    children:
      - model: ur5
        name_editing: {{prefix: "ur5_"}}
        joint: {{parent: torso_2_link, name: torso_to_ur5, xyz: [0.1, 0, 0.3]}}
      - model: talos
        take_leaf: arm_left_1_link
        mirror: {{plane: [0, 1, 0], name_replacements: {{"left": "mirrored"}}}}
        joint: {{parent: torso_2_link, name: torso_to_mirrored_arm, xyz: [-0.1, 0, 0.3]}}
  export_config:
    - {{type: urdf, mesh_format: stl}}
    - {{type: sdf, mesh_format: stl}}
    - {{type: smurf}}
    - {{type: joint_limits}}
"""


def build(spec: Path, out: Path, cache: Path, profile: Path) -> tuple[float, float, dict[str, float]]:
    """One `mpc compile` in a fresh process: (seconds, peak RSS in MiB, seconds per stage; "cpu" is
    the CPU time of the process and its mesh workers)."""
    profile.unlink(missing_ok=True)
    env = {**os.environ, "MPC_CACHE_DIR": str(cache), "MPC_PROFILE": str(profile)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # users' builds import compiled bytecode
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    child = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o", str(out)],
                             env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.perf_counter() - t0
    output = child.stdout.read().decode() if child.stdout else ""
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"the build failed:\n{output}")
    stages: dict[str, float] = {}
    for line in (profile.read_text().splitlines() if profile.exists() else []):  # an mpc without stages
        for name, value in json.loads(line)["stages"].items():
            stages[name] = stages.get(name, 0.0) + value
    stages["startup"] = max(0.0, seconds - sum(stages.values()))
    stages["cpu"] = usage.ru_utime + usage.ru_stime
    return seconds, usage.ru_maxrss / 1024, stages  # the child's peak, its mesh workers' included


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="runs of each of cold and warm (default 5)")
    args = parser.parse_args()
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "pip install example-robot-data"
    robots = erd / "robots"
    with tempfile.TemporaryDirectory() as tmp_:
        tmp = Path(tmp_)
        spec = tmp / "assembly.yml"
        spec.write_text(DEFINITION.format(talos=robots / "talos_data/robots/talos_full_v2.urdf",
                                          ur5=robots / "ur_description/urdf/ur5_robot.urdf"))
        text = spec.read_text()
        build(spec, tmp / "out", tmp / "cache-first", tmp / "profile")  # compiles Python's bytecode
        results: dict[str, list[tuple[float, float, dict[str, float]]]] = {
            "cold": [], "warm": [], "edited": []}
        for run in range(args.runs):
            cache = tmp / f"cache{run}"
            results["cold"].append(build(spec, tmp / "out", cache, tmp / "profile"))
            results["warm"].append(build(spec, tmp / "out", cache, tmp / "profile"))
            spec.write_text(f"{text}# edit {run}\n")  # a new definition: the front end runs
            time.sleep(0.05)
            results["edited"].append(build(spec, tmp / "out", cache, tmp / "profile"))
            spec.write_text(text)
        links = (tmp / "out/urdf/talos_assembly.urdf").read_text().count("<link ")
        print(f"the assembly: {links} links; load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        names = sorted({n for runs in results.values() for _, _, s in runs for n in s} - {"cpu"},
                       key=lambda n: -statistics.median(s.get(n, 0.0) for _, _, s in results["cold"]))
        for label, runs in results.items():
            seconds = statistics.median(r[0] for r in runs)
            peak = max(r[1] for r in runs)
            cpu = statistics.median(s["cpu"] for _, _, s in runs)
            print(f"{label}: {seconds:6.3f} s (median of {len(runs)}; min {min(r[0] for r in runs):.3f}), "
                  f"CPU {cpu:.3f} s, peak {peak:.0f} MiB")
            print("  " + ", ".join(f"{n} {statistics.median(s.get(n, 0.0) for _, _, s in runs):.3f}"
                                   for n in names))
        cold, warm, edited = (statistics.median(r[0] for r in results[k]) for k in ("cold", "warm", "edited"))
        print(f"goals: cold {cold:.2f} s / 2.0 s = {cold / 2.0:.2f}; warm {warm:.3f} s / 0.30 s = "
              f"{warm / 0.30:.2f} (edited {edited:.3f} s / 0.30 s = {edited / 0.30:.2f}); "
              f"peak {max(r[1] for v in results.values() for r in v):.0f} MiB / 300 MiB")


if __name__ == "__main__":
    main()
