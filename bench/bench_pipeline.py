"""`mpc run` on the twelve-model fleet (examples/fleet): cold build with -j1 and -j2, the
no-op rebuild, and peak memory (the largest process, and the whole process tree at once).

Cold: an empty build folder and an empty mesh cache. No-op: the same run again, nothing
changed (the median of five; target: under 1 s). Times are wall-clock times of the `mpc`
command as users run it, Python start-up included. Run: python bench/bench_pipeline.py
"""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

FLEET = Path(__file__).resolve().parents[1] / "examples" / "fleet"
PAGE = os.sysconf("SC_PAGE_SIZE")


def _tree_rss(root: int) -> int:
    """Resident memory of `root` and all its descendants now, in bytes."""
    parent: dict[int, int] = {}
    rss: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        parent[int(entry)] = int(fields[1])
        rss[int(entry)] = int(fields[21]) * PAGE
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += rss.get(pid, 0)
        todo.extend(p for p, pp in parent.items() if pp == pid)
    return total


def run(pipeline: Path, *args: str, env: dict[str, str]) -> tuple[float, float, int]:
    """Wall time and CPU time (user + system, the runner alone) of one `mpc run`, and the
    peak memory of its process tree."""
    peak = 0
    done = threading.Event()
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "run", str(pipeline), *args],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)

    def sample() -> None:
        nonlocal peak
        while not done.is_set():
            peak = max(peak, _tree_rss(proc.pid))
            time.sleep(0.02)

    sampler = threading.Thread(target=sample)
    sampler.start()
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    done.set()
    sampler.join()
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert proc.returncode == 1, "the fleet has one broken model: exit status 1 expected"
    return seconds, usage.ru_utime + usage.ru_stime, peak


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        print("mpc run examples/fleet/pipeline.yml (12 models: 10 built, 1 broken, 1 skipped)")
        for jobs in ("1", "2"):
            folder = base / f"j{jobs}"
            shutil.copytree(FLEET, folder)
            env = {**os.environ, "MPC_CACHE_DIR": str(base / f"cache-j{jobs}")}
            seconds, _, peak = run(folder / "pipeline.yml", "-j", jobs, env=env)
            print(f"cold, -j{jobs}:        {seconds:6.2f} s   peak memory of the process tree "
                  f"{peak / 2**20:4.0f} MB")
        noops = [run(folder / "pipeline.yml", env=env) for _ in range(5)]
        wall = statistics.median(n[0] for n in noops)
        cpu = statistics.median(n[1] for n in noops)
        print(f"no-op rebuild:    {wall:6.2f} s   (median of 5, wall; CPU {cpu:.2f} s; "
              f"min wall {min(n[0] for n in noops):.2f} s)")
        largest = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        print(f"largest process:  {largest:6.0f} MB  (peak resident memory of one mpc process)")


if __name__ == "__main__":
    main()
