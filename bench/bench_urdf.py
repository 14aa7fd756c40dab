"""Time to read talos_full_v2.urdf into the IR and emit it as canonical URDF (no mesh copies).

Targets: under 30 ms for read + emit (issue 2); at most 4× lxml's own parse + serialize of
the same file, in the same process (issue 34; 6× in issue 19), printed as a ratio of the medians.
The ratio is printed twice: of wall times, and of the thread's CPU times. On a busy machine the
wall time of a read (10 ms) holds the waits of the processes the scheduler ran in between,
which lxml's 2 ms seldom do: the ratio of CPU times is the one to judge there.

Each side frees what it made within its own time: lxml's tree is freed as `tostring` returns,
and mpc's IR (with the parsed file its spans hold) right after its write. Until 2026-11-28 the
IR was freed when the next read's result replaced it, so every read ran beside the previous
read's IR and then freed it, cold: 0.6-0.9 ms more per repetition than freeing it at once,
which lxml's side never paid (bench/README.md, 2026-11-28).

Run: python bench/bench_urdf.py [repetitions]
"""

from __future__ import annotations

import os
import statistics
import sys
import time

from lxml import etree

from mpc.backends import urdf
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.ir.geometry import Mesh


def main(reps: int = 30) -> None:
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "pip install example-robot-data"
    path = erd / "robots/talos_data/robots/talos_full_v2.urdf"

    def name(mesh: Mesh) -> str:
        return mesh.source.uri

    reads, emits, lxml_alone, cpu, lxml_cpu = [], [], [], [], []
    data = path.read_bytes()
    for _ in range(reps):
        c0, t0 = time.thread_time(), time.perf_counter()
        etree.tostring(etree.fromstring(data))
        lxml_alone.append((time.perf_counter() - t0) * 1e3)
        lxml_cpu.append((time.thread_time() - c0) * 1e3)
        c0, t0 = time.thread_time(), time.perf_counter()
        robot = urdf.read(path, Sink())
        t1 = time.perf_counter()
        assert robot is not None
        urdf.to_string(robot, name)
        links, joints = len(robot.links), len(robot.joints)
        del robot  # freed as lxml's tree is, within the time
        t2 = time.perf_counter()
        cpu.append((time.thread_time() - c0) * 1e3)
        reads.append((t1 - t0) * 1e3)
        emits.append((t2 - t1) * 1e3)
    total = [r + e for r, e in zip(reads, emits, strict=True)]
    print(f"talos_full_v2.urdf ({links} links, {joints} joints), "
          f"median of {reps}:")
    print(f"  read  {statistics.median(reads):6.2f} ms")
    print(f"  emit  {statistics.median(emits):6.2f} ms   (and the IR freed)")
    print(f"  total {statistics.median(total):6.2f} ms   (target < 30 ms)")
    lxml_ms = statistics.median(lxml_alone)
    print(f"  lxml parse + serialize alone {lxml_ms:6.2f} ms: mpc's read + emit is "
          f"{statistics.median(total) / lxml_ms:.2f}× (target ≤ 4×; load average {os.getloadavg()[0]:.1f})")
    cpu_ms, lxml_cpu_ms = statistics.median(cpu), statistics.median(lxml_cpu)
    print(f"  CPU time: mpc {cpu_ms:6.2f} ms, lxml {lxml_cpu_ms:6.2f} ms: "
          f"{cpu_ms / lxml_cpu_ms:.2f}× (target ≤ 4×)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 30)
