"""Wall time of the solid geometry on real models: physical_validity's findings without and
with the plausibility check (a union of each link's collision shapes, manifold3d), and the
union of TALOS's left leg at q = 0.

Run: python bench/bench_solids.py [runs]
"""

from __future__ import annotations

import statistics
import sys
import time

from mpc.backends.urdf_reader import read
from mpc.checks.validity import findings, geometric_problems
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.mesh_props import solid
from mpc.ir.solids import union

MODELS = ("talos_data/robots/talos_full_v2.urdf", "ur_description/urdf/ur5_robot.urdf",
          "solo_description/robots/solo12.urdf")


def _median(fn, runs: int) -> float:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main(runs: int = 3) -> None:
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "example-robot-data is not installed"
    for model in MODELS:
        robot = read(erd / "robots" / model, Sink())
        assert robot is not None
        before = _median(lambda r=robot: geometric_problems(r, 0.003), runs)
        after = _median(lambda r=robot: findings(r, 0.003), runs)
        print(f"{model}: {len(robot.links)} links, physical_validity {before:.2f} s, "
              f"with plausibility {after:.2f} s (median of {runs})")
    talos = read(erd / "robots" / MODELS[0], Sink())
    assert talos is not None

    def leg() -> None:
        legs = [name for name in talos.links if name.startswith("leg_left_")]
        union([(solid(c.geometry), link_in_root(talos, name) @ pose_matrix(c.origin))
               for name in legs for c in talos.links[name].collisions])

    print(f"union of talos's left leg (6 meshes): {_median(leg, runs):.2f} s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
