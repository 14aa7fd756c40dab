"""Wall time of the model tests on talos (60 links) compared with itself: every test of
`mpc test`, the model compiled beforehand (compiling is bench_meshes.py's business); then
the same with the tests of issue 33 added (joint_limits, the budgets, effort_covers_gravity,
self_collision; the definition has auto_bitmask and a named pose), run in turns with the
first, and the ratio of the two medians (the goal: at most 1.2).

Last, issue 34's goal for the whole command: `mpc test` of each definition on its compiled
output (`--built`), as a user runs it (a process of its own, with compiled bytecode): wall and CPU
seconds and the peak resident memory, medians of the runs, beside the goal (≤ 2 s, ≤ 400 MiB).

Run: python bench/bench_test.py [runs]
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpc.checks import run_model_tests
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver

TESTS = """\
      - process_double_check
      - load_in_pybullet
      - compare_link_masses
      - compare_link_transformations
      - compare_amount_joints
      - hyrodynChecks:
          - load_in_hyrodyn
          - compare_masses
          - compare_com
          - compare_torques
          - compare_link_positions
          - move_hyrodyn_model: 0.3
          - compare_torques
"""


ADDED = """\
      - joint_limits: {mirrored: [left, right]}
      - max_mesh_faces: 50000
      - max_mesh_bytes: 20000000
      - max_collisions_per_link: 2
      - effort_covers_gravity
      - self_collision
"""
# A named pose (elbows and knees bent) for effort_covers_gravity and self_collision; the bitmasks make
# self_collision test the pairs that may collide (TALOS's hands touch its thighs at q = 0).
EXTRA = """\
  collisions:
    auto_bitmask: true
  poses:
    bent: {arm_left_4_joint: -1.0, arm_right_4_joint: -1.0, leg_left_4_joint: 0.6,
           leg_right_4_joint: 0.6}
"""


def _compiled(folder: Path, name: str, erd: Path, tests: str, extra: str) -> object:
    (folder / f"{name}.yml").write_text(
        "model:\n  robotname: talos\n  modelname: talos-model\n  input_models:\n    base:\n"
        f"      basefile: \"{erd / 'robots/talos_data/robots/talos_full_v2.urdf'}\"\n"
        f"  assemble:\n    model: base\n{extra}  test:\n    compare_model:\n      path: {name}\n"
        "    tests:\n" + tests)
    result = compile_model(folder / f"{name}.yml", Sink(), Options(out=folder / name))
    assert result.out is not None and result.program is not None
    return result


def main(runs: int = 5) -> None:
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "example-robot-data is not installed"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        before = _compiled(folder, "before", erd, TESTS, EXTRA)
        after = _compiled(folder, "after", erd, TESTS + ADDED, EXTRA)
        times: dict[str, list[float]] = {"before": [], "after": []}
        cpu: dict[str, list[float]] = {"before": [], "after": []}
        counts = {}
        for i in range(runs + 1):
            for name, result in (("before", before), ("after", after)):
                start, start_cpu = time.perf_counter(), time.process_time()
                protocol = run_model_tests(result.program, result.out, Sink(),  # type: ignore[attr-defined]
                                           workdir=folder / "work", robot=result.robot)  # type: ignore[attr-defined]
                if i:  # the first run imports Pinocchio, PyBullet and coal
                    times[name].append(time.perf_counter() - start)
                    cpu[name].append(time.process_time() - start_cpu)
                assert not protocol.failed, protocol.markdown()
                counts[name] = len(protocol.results)
        for name in ("before", "after"):
            whole_command(folder, name, runs)
    for name in times:
        print(f"mpc test talos against itself, {name} issue 33 ({counts[name]} tests), median of {runs}: "
              f"{statistics.median(times[name]) * 1000:.0f} ms (min {min(times[name]) * 1000:.0f} ms), "
              f"CPU {statistics.median(cpu[name]) * 1000:.0f} ms")
    ratio = statistics.median(times["after"]) / statistics.median(times["before"])
    ratio_cpu = statistics.median(cpu["after"]) / statistics.median(cpu["before"])
    print(f"ratio after / before: {ratio:.3f} (min / min {min(times['after']) / min(times['before']):.3f}; "
          f"CPU {ratio_cpu:.3f}; goal ≤ 1.2)")


_TIMER = """
import os, subprocess, sys, time
start = time.perf_counter()
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
assert os.waitstatus_to_exitcode(status) == 0, sys.argv[1:]
print(time.perf_counter() - start, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024)
"""


def whole_command(folder: Path, name: str, runs: int) -> None:
    """`mpc test NAME.yml --built NAME` in a process of its own: wall, CPU, peak memory."""
    mpc = str(Path(sys.executable).with_name("mpc"))
    command = [mpc, "test", str(folder / f"{name}.yml"), "--built", str(folder / name),
               "-o", str(folder / "protocol")]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    walls, cpus, peaks = [], [], []
    for i in range(runs + 1):
        # Started by a small Python of its own: Linux gives a child the peak resident memory of
        # the process it was forked from (this one holds the models of the runs above, 480 MiB),
        # and the child keeps it through exec.
        timer = subprocess.run([sys.executable, "-c", _TIMER, *command], env=env, check=True,
                               capture_output=True, text=True)
        wall, cpu_, peak = map(float, timer.stdout.split())
        if i:  # the first run writes bytecode and fills the mesh cache
            walls.append(wall)
            cpus.append(cpu_)
            peaks.append(peak)
    med = statistics.median
    print(f"mpc test talos, {name} issue 33 (a process of its own), median of {runs}: "
          f"wall {med(walls):.2f} s (goal ≤ 2), CPU {med(cpus):.2f} s, "
          f"peak memory {med(peaks):.0f} MiB (goal ≤ 400)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
