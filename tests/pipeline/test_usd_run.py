"""`mpc run` of a definition with a usd export: built, counted with the model's files, kept in
the cache (a second run builds nothing and the output keeps its bytes)."""

from __future__ import annotations

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
