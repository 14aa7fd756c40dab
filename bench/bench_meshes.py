"""Cold and warm build of talos_full_v2 with STL and OBJ exports, and the peak memory.

Cold: an empty mesh cache, so the 48 OBJ meshes are computed (in a process pool); warm:
the same build again, which only copies from the cache. Run: python bench/bench_meshes.py
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpc.core.packages import PackageResolver


def main() -> None:
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "pip install example-robot-data"
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "talos.yml"
        spec.write_text(f"""model:
  robotname: talos
  modelname: talos-bench
  input_models: {{talos: {{basefile: "{erd / 'robots/talos_data/robots/talos_full_v2.urdf'}"}}}}
  assemble: {{model: talos}}
  export_config:
    - {{type: urdf, mesh_format: stl}}
    - {{type: urdf, mesh_format: obj, filename_suffix: _obj}}
""")
        env = {**os.environ, "MPC_CACHE_DIR": str(Path(tmp) / "cache")}
        for label in ("cold", "warm"):
            out = Path(tmp) / label
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(spec), "-o", str(out)],
                           check=True, env=env, capture_output=True)
            print(f"{label:5s} build: {time.perf_counter() - t0:6.2f} s")
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"peak memory of one build process: {peak:.0f} MiB")


if __name__ == "__main__":
    main()
