"""Wall time of the model tests on talos (60 links) compared with itself: every test of
`mpc test`, the model compiled beforehand (compiling is bench_meshes.py's business).

Run: python bench/bench_test.py [runs]
"""

from __future__ import annotations

import statistics
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


def main(runs: int = 5) -> None:
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "example-robot-data is not installed"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "talos.yml").write_text(
            "model:\n  robotname: talos\n  modelname: talos-model\n  input_models:\n    base:\n"
            f"      basefile: \"{erd / 'robots/talos_data/robots/talos_full_v2.urdf'}\"\n"
            "  assemble:\n    model: base\n  test:\n    compare_model:\n      path: out\n"
            "    tests:\n" + TESTS)
        result = compile_model(folder / "talos.yml", Sink(), Options(out=folder / "out"))
        assert result.out is not None and result.program is not None
        times = []
        for i in range(runs + 1):
            start = time.perf_counter()
            protocol = run_model_tests(result.program, result.out, Sink(), workdir=folder / "work",
                                       robot=result.robot)
            if i:  # the first run imports Pinocchio and PyBullet
                times.append(time.perf_counter() - start)
            assert not protocol.failed, protocol.markdown()
    print(f"mpc test talos against itself ({len(protocol.results)} tests), median of {runs}: "
          f"{statistics.median(times) * 1000:.0f} ms (min {min(times) * 1000:.0f} ms)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
