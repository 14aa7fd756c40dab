"""`mpc run` on the twelve-model fleet (examples/fleet) and on 50 models made of copies of
it: cold build with -j1 and -j2 and their ratio, the no-op rebuild, and peak memory (the
largest process, and the whole process tree at once).

Cold: an empty build folder and an empty mesh cache. No-op: the same run again, nothing
changed (the median of five). Targets (issue 19): the 50 models at -j2 at least 1.6× faster
than at -j1; the fleet's no-op rebuild at most 0.25 s. Times are wall-clock times of the
`mpc` command as users run it, Python start-up included; the machine's load average is
printed with them. Run: python bench/bench_pipeline.py [fleet] [50] [--runs N]   (default: both, 3)
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

import yaml

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


def run(pipeline: Path, *args: str, env: dict[str, str], sample: bool = False) -> tuple[float, float, int]:
    """Wall time and CPU time (user + system, the runner alone) of one `mpc run`, and, when
    `sample`, the peak memory of its process tree (else 0). A timed run is not sampled: the
    sampler reads /proc every 20 ms, a tenth of a core, which a -j2 run on two cores would
    lose and a -j1 run would not."""
    peak = 0
    done = threading.Event()
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "run", str(pipeline), *args],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)

    def sample_memory() -> None:
        nonlocal peak
        while not done.is_set():
            peak = max(peak, _tree_rss(proc.pid))
            time.sleep(0.02)

    sampler = threading.Thread(target=sample_memory) if sample else None
    if sampler is not None:
        sampler.start()
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    done.set()
    if sampler is not None:
        sampler.join()
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert proc.returncode == 1, "the fleet has one broken model: exit status 1 expected"
    return seconds, usage.ru_utime + usage.ru_stime, peak


def copies(folder: Path, count: int) -> Path:
    """A pipeline of `count` models in `folder`: the fleet's definitions again and again, each
    copy with its own modelnames and derived_base files (its meshes are the fleet's)."""
    shutil.copytree(FLEET, folder)
    fleet = yaml.safe_load((FLEET / "pipeline.yml").read_text())["pipeline"]
    stems = sorted((Path(f).stem for f in fleet["model_definitions"]),
                   key=lambda stem: stem not in ("pendulum", "finger"))  # a partial copy: these two
    written = []
    for k in range(count):
        stem = stems[k % len(stems)]
        copy = k // len(stems)
        text = (FLEET / f"{stem}.yml").read_text()
        text = re.sub(r"modelname: (\w+)", rf"modelname: \1_c{copy}", text)
        text = re.sub(r"derived_base: (\w+)\.yml", rf"derived_base: \1_c{copy}.yml", text)
        (folder / f"{stem}_c{copy}.yml").write_text(text)
        written.append(f"{stem}_c{copy}.yml")
    pipeline = {"pipeline": {"root": ".", "model_definitions": written,
                             "default_export_config": fleet["default_export_config"]}}
    (folder / "pipeline.yml").write_text(yaml.safe_dump(pipeline, sort_keys=False))
    return folder / "pipeline.yml"


def cold_and_noop(base: Path, name: str, make: Callable[[Path], Path], noop: bool, runs: int) -> None:
    """Cold builds at -j1 and -j2, `runs` of each taken in turns (the machine's speed drifts:
    turns share the drift), their medians and the ratio of the medians; one more of each for
    its peak memory; then the no-op of the last timed build."""
    times: dict[str, list[float]] = {"1": [], "2": []}
    for turn in range(runs):
        for jobs in ("1", "2"):
            folder = base / f"{name}-j{jobs}-{turn}"
            pipeline = make(folder)
            env = {**os.environ, "MPC_CACHE_DIR": str(base / f"cache-{name}-j{jobs}-{turn}")}
            os.sync()  # the last run's files written back first, not during this one
            seconds, _, _ = run(pipeline, "-j", jobs, env=env)
            times[jobs].append(seconds)
            print(f"cold, -j{jobs}:        {seconds:6.2f} s   (load average {os.getloadavg()[0]:.1f})")
    for jobs in ("1", "2"):  # one more of each, its memory sampled (not timed: see run)
        cache = base / f"cache-{name}-j{jobs}-memory"
        _, _, peak = run(make(base / f"{name}-j{jobs}-memory"), "-j", jobs,
                         env={**os.environ, "MPC_CACHE_DIR": str(cache)}, sample=True)
        print(f"cold, -j{jobs}: peak memory of the process tree {peak / 2**20:4.0f} MB")
    j1, j2 = statistics.median(times["1"]), statistics.median(times["2"])
    print(f"-j2 vs -j1:       {j1 / j2:6.2f}×  (medians of {runs}: {j1:.2f} s / {j2:.2f} s; "
          f"target ≥ 1.6× for 50 models)")
    if noop:
        noops = [run(pipeline, env=env) for _ in range(5)]
        wall = statistics.median(n[0] for n in noops)
        cpu = statistics.median(n[1] for n in noops)
        print(f"no-op rebuild:    {wall:6.2f} s   (median of 5, wall; CPU {cpu:.2f} s; "
              f"min wall {min(n[0] for n in noops):.2f} s; target ≤ 0.25 s; load average "
              f"{os.getloadavg()[0]:.1f})")


def main(which: list[str], runs: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        if "fleet" in which:
            print("mpc run examples/fleet/pipeline.yml (12 models: 10 built, 1 broken, 1 skipped)")
            cold_and_noop(base, "fleet", lambda folder: copies(folder, 12), noop=True, runs=runs)
        if "50" in which:
            print("mpc run on 50 models: copies of the fleet (their meshes are the fleet's)")
            cold_and_noop(base, "50", lambda folder: copies(folder, 50), noop=False, runs=runs)
        largest = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        print(f"largest process:  {largest:6.0f} MB  (peak resident memory of one mpc process)")


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("which", nargs="*", help="fleet, 50 (default: both)")
    parser.add_argument("--runs", type=int, default=3, help="cold runs of each -j (default 3)")
    args = parser.parse_args()
    if not set(args.which) <= {"fleet", "50"}:
        parser.error(f"unknown: {' '.join(set(args.which) - {'fleet', '50'})}")
    main(args.which or ["fleet", "50"], args.runs)
