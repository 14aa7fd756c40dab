"""Time to read an MJCF robot of about 30 bodies into the IR (backends/mjcf_reader.py) against
MuJoCo's own `MjModel.from_xml_path` of the same file, in the same process, meshes in the
page cache (both read them once before timing).

Robot: gymnasium-robotics' Fetch (fetch/reach.xml: 32 bodies, 18 STL meshes, an include).
Target (issue 31): mpc's read at most 1.5× MuJoCo's load, printed as a ratio of the medians.
Run: python bench/bench_mjcf_read.py [repetitions]
"""

from __future__ import annotations

import importlib.util
import os
import statistics
import sys
import time
from pathlib import Path

import mujoco

from mpc.backends import mjcf_reader
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver


def main(reps: int = 20) -> None:
    spec = importlib.util.find_spec("gymnasium_robotics")
    assert spec is not None and spec.submodule_search_locations, "pip install gymnasium-robotics"
    root = Path(next(iter(spec.submodule_search_locations)))
    path = root / "envs/assets/fetch/reach.xml"
    resolver = PackageResolver()
    resolver.add_project(root)  # the robot's meshes lie in a folder beside its own
    ours, theirs = [], []
    robot = mjcf_reader.read(path, Sink(), resolver)  # warm: the files in the page cache
    model = mujoco.MjModel.from_xml_path(str(path))
    for _ in range(reps):
        t0 = time.perf_counter()
        mujoco.MjModel.from_xml_path(str(path))
        t1 = time.perf_counter()
        robot = mjcf_reader.read(path, Sink(), resolver)
        t2 = time.perf_counter()
        theirs.append((t1 - t0) * 1e3)
        ours.append((t2 - t1) * 1e3)
    assert robot is not None
    mine, mj = statistics.median(ours), statistics.median(theirs)
    print(f"fetch/reach.xml ({model.nbody} bodies, {model.nmesh} meshes; {len(robot.links)} links), "
          f"median of {reps}:")
    print(f"  MuJoCo MjModel.from_xml_path {mj:7.2f} ms")
    print(f"  mpc mjcf_reader.read         {mine:7.2f} ms")
    print(f"  ratio {mine / mj:.2f}× (target ≤ 1.5×; load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
