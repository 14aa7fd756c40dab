"""Wall time of the pictures: the render export of talos and UR5 (3 views, 640×480, cold and
warm mesh cache) and the visual diff of `mpc test` (talos against itself, 3 views, 480×360).

Run: python bench/bench_render.py
"""

from __future__ import annotations

import os
import tempfile
import time

from mpc.backends.render import draw_all
from mpc.backends.urdf_reader import read
from mpc.checks import pictures
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.core.span import Span
from mpc.ir.program import RenderExport, Tolerances

ERD = PackageResolver().find("example-robot-data") / "robots"  # type: ignore[operator]
ROBOTS = {"talos": ERD / "talos_data/robots/talos_full_v2.urdf",
          "ur5": ERD / "ur_description/urdf/ur5_robot.urdf"}


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        os.environ["MPC_CACHE_DIR"] = cache
        export = RenderExport(span=Span.of_file("bench"), poses=("zero",))
        for name, path in ROBOTS.items():
            robot = read(path, Sink())
            assert robot is not None
            for run in ("cold", "warm"):
                start = time.perf_counter()
                drawn = draw_all(robot, export, Sink())
                assert drawn is not None
                took = time.perf_counter() - start
                size = sum(len(b) for b in drawn.values()) / len(drawn) / 1024
                print(f"render {name} ({len(robot.links)} links), 3 views 640x480, {run} mesh cache: "
                      f"{took:.2f} s ({size:.0f} KiB a PNG)")
        talos = read(ROBOTS["talos"], Sink())
        start = time.perf_counter()
        diff = pictures.draw(talos, talos, Tolerances(), None, Sink(), tree=True)
        print(f"visual diff talos vs talos, 3 views 480x360 + kinematic tree: "
              f"{time.perf_counter() - start:.2f} s, {len(diff.files)} files")


if __name__ == "__main__":
    main()
