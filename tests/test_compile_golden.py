"""`mpc compile` of the repository's definitions and of the example-robot-data corpus against
recorded outputs (tests/golden.py): the digest of every file it writes and of its
diagnostics, as `mpc compile` prints them.

Cases: every definition of examples/ (the fleet's one at a time; broken.yml fails on purpose,
its diagnostics are recorded whole), every example of specs/ that compiles (in a copy of
specs/examples/, as tests/test_specs.py runs them), and every URDF of example-robot-data
through a one-input definition exporting URDF, SDF, MJCF and joint limits. A change in what
any export writes, byte for byte, shows as the files it changes; `MPC_UPDATE_GOLDEN=1`
records them again. Each test builds on an empty cache of its own.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from mpc.compiler.driver import Options, compile_model
from mpc.core import render
from mpc.core.diagnostics import Sink
from tests.conftest import ERD, write
from tests.golden import REPO, check_digests, check_text, digest, stable
from tests.test_specs import EXAMPLES, EXAMPLES_FOUND

DEFINITIONS = sorted(p for p in (REPO / "examples").rglob("*.yml") if p.name != "pipeline.yml")
SPEC_EXAMPLES = [e for e in EXAMPLES_FOUND if not e.later and not e.pipeline]
CORPUS = sorted(ERD.rglob("*.urdf"))
CORPUS_EXPORTS = """\
    - {type: urdf, mesh_format: input_type}
    - {type: sdf, mesh_format: input_type}
    - {type: mjcf, mesh_format: stl}
    - {type: joint_limits}
"""


def compiled(definition: Path, out: Path, tmp: Path) -> dict[str, str]:
    """`mpc compile DEFINITION --out OUT`: the digest of each file written (the build cache's
    own folder left out) and of the diagnostics (`(diagnostics)`, their text, as printed)."""
    sink = Sink()
    result = compile_model(definition, sink, Options(out=out))
    files = {} if result.out is None else {
        str(p.relative_to(out)): digest(stable(p.read_bytes().decode("utf-8", "surrogateescape"), tmp))
        for p in sorted(out.rglob("*")) if p.is_file() and ".mpc" not in p.relative_to(out).parts}
    text = stable(render.human(sink.diagnostics), tmp)
    return {"(diagnostics)": text, **files}


def _flat(case: str, outputs: dict[str, str]) -> dict[str, str]:
    """One entry a model file and one for the diagnostics; the mesh files (`meshes/` in any
    folder) in one entry for all, so that the record stays small."""
    flat = {f"{case} | (diagnostics)": digest(outputs["(diagnostics)"])}
    meshes = [f"{name} {value}" for name, value in outputs.items() if "meshes" in Path(name).parts]
    for name, value in outputs.items():
        if name != "(diagnostics)" and "meshes" not in Path(name).parts:
            flat[f"{case} | {name}"] = value
    if meshes:
        flat[f"{case} | meshes ({len(meshes)} files)"] = digest("\n".join(meshes))
    return flat


@pytest.fixture
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))


@pytest.mark.usefixtures("own_cache")
def test_repository_definitions_compile_as_recorded(tmp_path: Path) -> None:
    found: dict[str, str] = {}
    for definition in DEFINITIONS:
        case = str(definition.relative_to(REPO))
        outputs = compiled(definition, tmp_path / "out" / case, tmp_path)
        found |= _flat(case, outputs)
        if definition.name == "broken.yml":
            check_text("compile/broken_diagnostics", outputs["(diagnostics)"])
    folder = tmp_path / "specs"
    shutil.copytree(EXAMPLES, folder, ignore=shutil.ignore_patterns("*.ir"))
    for example in SPEC_EXAMPLES:
        path = write(folder / f"{example.name}.yml", example.text)
        outputs = compiled(path, tmp_path / example.name, tmp_path)
        found |= _flat(f"specs {example.page}:{example.name}", outputs)
    assert len(DEFINITIONS) >= 14 and len(SPEC_EXAMPLES) >= 30
    check_digests("compile_definitions", found)


@pytest.mark.long
@pytest.mark.usefixtures("own_cache")
def test_example_robot_data_compiles_as_recorded(tmp_path: Path) -> None:
    found: dict[str, str] = {}
    for urdf in CORPUS:
        case = str(urdf.relative_to(ERD))
        definition = tmp_path / f"{urdf.stem}.yml"
        definition.write_text(f"model:\n  robotname: {urdf.stem}\n  modelname: {urdf.stem}\n"
                              f"  input_models: {{base: {{basefile: \"{urdf}\"}}}}\n"
                              f"  assemble: {{model: base}}\n  export_config:\n{CORPUS_EXPORTS}")
        found |= _flat(case, compiled(definition, tmp_path / "out" / urdf.stem, tmp_path))
    assert len(CORPUS) > 60
    check_digests("compile_example_robot_data", found)
