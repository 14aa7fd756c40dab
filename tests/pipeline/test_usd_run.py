"""`mpc run` of a definition with a usd export: built, counted with the model's files, kept in
the cache (a second run builds nothing and the output keeps its bytes)."""

from __future__ import annotations

import os
from pathlib import Path

from tests.conftest import write
from tests.fixtures import arm
from tests.pipeline.helpers import run_json


def test_mpc_run_builds_lists_and_keeps_a_usd_export(tmp_path: Path) -> None:
    project = tmp_path / "project"
    arm(project)
    write(project / "arm.yml", """
        model:
          robotname: arm
          modelname: arm-model
          input_models: {arm: {basefile: arm.urdf}}
          assemble: {model: arm}
          export_config:
            - type: usd
        """)
    pipeline = write(project / "pipeline.yml", """
        pipeline:
          model_definitions: [arm.yml]
          root: .
        """)
    first = run_json(pipeline, cache=tmp_path / "cache", cwd=project)
    assert first.returncode == 0 and first.state("arm-model") == "ok"
    out = project / "build" / "arm-model"
    usd = sorted(str(p.relative_to(out)) for p in (out / "usd").rglob("*") if p.is_file())
    assert usd == ["usd/arm.usda", "usd/arm_payload/contents.usda", "usd/arm_payload/geometry.usdc",
                   "usd/arm_payload/materials.usda", "usd/arm_payload/physics.usda"]
    finish = next(e for e in first.events if e["event"] == "finish")
    files = sum(1 for p in out.rglob("*") if p.is_file() and "meshes" not in p.parts)
    assert finish["stages"]["compile"]["details"] == {"files": files, "meshes": 0}
    before = {p: p.read_bytes() for p in (out / "usd").rglob("*") if p.is_file()}
    second = run_json(pipeline, cache=tmp_path / "cache", cwd=project)
    assert second.returncode == 0 and second.state("arm-model") == "cached"
    assert {p: p.read_bytes() for p in (out / "usd").rglob("*") if p.is_file()} == before


WATCH = """
import sys
import os
from pathlib import Path

from mpc.cli.main import main as mpc_main
from mpc.pipeline import worker

started = worker.main


def main(job, *args):  # noqa: ANN001, ANN202
    with open(sys.argv[1], "a") as seen:  # what the forked worker has before it builds
        seen.write(f"{job.model} {'pxr.Sdf' in sys.modules} {'mpc.backends.usd_stage' in sys.modules}\\n")
    started(job, *args)


worker.main = main
sys.exit(mpc_main(["run", sys.argv[2], "-j", "1"]))
"""


def _watched_run(tmp_path: Path, names: tuple[str, ...], exports: tuple[str, ...], script: str,
                 environ: dict[str, str]) -> list[str]:
    """`mpc run -j 1` of one arm model per name with these exports, each worker noting what
    `script` (WATCH or a variant) says it has before it builds; those notes, in build order."""
    import subprocess
    import sys

    project = tmp_path / "project"
    arm(project)
    for name in names:
        write(project / f"{name}.yml", f"""
            model:
              robotname: arm
              modelname: {name}
              input_models: {{arm: {{basefile: arm.urdf}}}}
              assemble: {{model: arm}}
              export_config:
            """.rstrip(" ") + "".join(f"                {line}\n" for line in exports))
    pipeline = write(project / "pipeline.yml", f"""
        pipeline:
          model_definitions: [{", ".join(f"{n}.yml" for n in names)}]
          root: .
        """)
    seen = tmp_path / "seen.txt"
    environ = {**environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", script, str(seen), str(pipeline)], cwd=project,
                          capture_output=True, text=True, env=environ)
    assert done.returncode == 0, done.stdout + done.stderr
    return seen.read_text().splitlines()


def test_later_workers_share_what_the_first_imported(tmp_path: Path) -> None:
    """The runner imports what a finished worker imported (usd-core, the usd backend) before it
    forks the next: three USD models, one at a time, import usd-core once."""
    lines = _watched_run(tmp_path, ("one", "two", "three"), ("- type: usd",), WATCH, dict(os.environ))
    assert sorted(line.split()[1:] == ["False", "False"] for line in lines) == [False, False, True]
    assert sorted(line.split()[1:] == ["True", "True"] for line in lines) == [False, True, True]


def test_sharing_leaves_the_environment_a_build_is_kept_by(tmp_path: Path) -> None:
    """A render imports mujoco.egl, which sets PYOPENGL_PLATFORM for its process: the runner
    shares no such module and keeps its environment (what a build is kept by), so that the
    next worker starts with the environment the first had."""
    script = WATCH.replace("'pxr.Sdf' in sys.modules", "'PYOPENGL_PLATFORM' in os.environ").replace(
        "import sys\n", "import os\nimport sys\n", 1)
    environ = {k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"}
    lines = _watched_run(tmp_path, ("one", "two"), ("- type: render", "  views: [front]"), script, environ)
    assert [line.split()[1] for line in lines] == ["False", "False"]
