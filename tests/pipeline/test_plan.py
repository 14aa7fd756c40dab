"""Planning a pipeline: derived_base edges, cycles, clashing names, missing files, the
pipeline's defaults and where relative paths point."""

from __future__ import annotations

import textwrap
from pathlib import Path

from mpc.compiler import inherit
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Sink
from mpc.pipeline import dag
from mpc.pipeline.defaults import PipelineDefaults
from mpc.pipeline.plan import load_plan
from tests.conftest import ERD, write
from tests.pipeline.helpers import mpc, run_json

PENDULUM = ERD / "double_pendulum_description/urdf/double_pendulum_simple.urdf"


def _model(name: str, *, base: str = f'basefile: "{PENDULUM}"') -> str:
    return f"model:\n  robotname: {name}\n  modelname: {name}\n  input_models: {{b: {{{base}}}}}\n" \
           "  assemble: {model: b}\n"


def test_order_cycles_and_dependants() -> None:
    parents = {"c": ("b",), "b": ("a",), "a": (), "d": ("b", "c"), "x": ("y",), "y": ("x",), "z": ("y",)}
    assert dag.order(parents) == ["a", "b", "c", "d"]
    assert dag.cycles(parents) == [["x", "y", "x"]]
    assert dag.descendants(parents, "b") == {"c", "d"}


def test_a_cycle_fails_its_models_and_names_the_loop_and_the_rest_builds(tmp_path: Path) -> None:
    write(tmp_path / "a.yml", _model("a", base="derived_base: b.yml"))
    write(tmp_path / "b.yml", _model("b", base="derived_base: a.yml"))
    write(tmp_path / "c.yml", _model("c", base="derived_base: b.yml"))
    write(tmp_path / "d.yml", _model("d"))
    write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [a.yml, b.yml, c.yml, "
          "d.yml]\n")
    run = run_json(tmp_path / "pipeline.yml", cache=tmp_path / "cache")
    assert run.states() == {"a": "failed", "b": "failed", "c": "skipped", "d": "ok"}
    [diag] = run.status["models"]["a"]["stages"]["compile"]["diagnostics"]
    assert (diag["code"], diag["message"]) == ("E0611", "derived_base cycle: a.yml → b.yml → a.yml")
    span = diag["span"]
    assert (span["file"], span["line"], span["col"]) == (str(tmp_path / "a.yml"), 4, 36)
    assert run.status["models"]["c"]["stages"]["compile"]["reason"] == "derived_base 'b' failed"


def test_clashing_modelnames_missing_files_and_parents_outside_the_pipeline(tmp_path: Path) -> None:
    write(tmp_path / "one.yml", _model("same"))
    write(tmp_path / "two.yml", _model("same"))
    write(tmp_path / "outside.yml", _model("outside"))
    write(tmp_path / "child.yml", _model("child", base="derived_base: outside.yml"))
    write(tmp_path / "pipeline.yml", """
        pipeline:
          root: .
          model_definitions: [one.yml, two.yml, gone.yml, child.yml, one.yml]
        """)
    sink = Sink()
    plan = load_plan(tmp_path / "pipeline.yml", sink)
    assert plan is not None
    [twice] = sink.diagnostics
    assert (twice.code, twice.message, twice.span.line, twice.span.col) == (
        "W0611", "model definition 'one.yml' is listed twice; it is built once", 3, 62)
    assert list(plan.models) == ["same", "same (two.yml)", "gone", "child"]
    [clash] = plan.models["same (two.yml)"].diagnostics
    assert (clash.code, clash.message) == ("E0610", "model definitions 'one.yml' and 'two.yml' both build "
                                           "model 'same'")
    [gone] = plan.models["gone"].diagnostics
    assert (gone.code, gone.message) == ("E0601", "model definition 'gone.yml' does not exist")
    [outside] = plan.models["child"].diagnostics
    assert outside.code == "W0610" and not plan.models["child"].failed
    assert outside.message == ("derived_base 'outside.yml' is not one of the pipeline's model_definitions; "
                               "it is compiled in memory for this model but not built on its own")


def test_pipeline_defaults_merge_under_each_model(tmp_path: Path) -> None:
    pipeline = write(tmp_path / "pipeline.yml", """
        pipeline:
          model_definitions: [m.yml]
          default_export_config:
            - {type: urdf, mesh_format: stl}
          default_test:
            tolerances: {mass: 0.05, rad: 0.1}
            tests: [topological_self_consistency]
          default_deployment:
            mr_title: from the pipeline
            keep_files: [README.md]
        """)
    model = write(tmp_path / "m.yml", """
        model:
          modelname: m
          test:
            tolerances: {mass: 0.02}
            tests: [total_mass]
          deployment:
            keep_files: [LICENSE]
        """)
    sink = Sink()
    doc = source.load(model, sink)
    assert doc is not None
    merged = PipelineDefaults(source.load(pipeline, sink))(inherit.resolve(doc, model, sink))
    m = merged.data["model"]
    assert m["export_config"] == [{"type": "urdf", "mesh_format": "stl"}]
    assert m["test"] == {"tolerances": {"mass": 0.02, "rad": 0.1},
                         "tests": ["topological_self_consistency", "total_mass"]}
    assert m["deployment"] == {"mr_title": "from the pipeline", "keep_files": ["README.md", "LICENSE"]}
    # Each value keeps the place where it was written.
    assert merged.value_span(("model", "test", "tolerances", "rad")).file == str(pipeline)
    assert merged.value_span(("model", "test", "tolerances", "mass")).file == str(model)
    assert merged.value_span(("model", "test", "tests", 1)).file == str(model)
    assert merged.value_span(("model", "export_config", 0, "mesh_format")).line == 4
    own = write(tmp_path / "own.yml", "model:\n  export_config: [{type: sdf, mesh_format: stl}]\n")
    kept = PipelineDefaults(source.load(pipeline, sink))(source.load(own, sink))
    assert kept.data["model"]["export_config"] == [{"type": "sdf", "mesh_format": "stl"}]
    assert not sink.diagnostics


def test_relative_paths_follow_the_file_that_wrote_them_from_any_working_folder(tmp_path: Path) -> None:
    """The pipeline in ci/, definitions in models/, a defaults file in models/common/ naming
    the URDF next to itself; run from an unrelated folder."""
    (tmp_path / "models/common").mkdir(parents=True)
    (tmp_path / "models/common/robot.urdf").write_text(PENDULUM.read_text())
    write(tmp_path / "models/common/base.yml", """
        default_model:
          input_models: {b: {basefile: robot.urdf}}
          assemble: {model: b}
        """)
    write(tmp_path / "models/arm.yml", "defaults: common/base.yml\nmodel: {robotname: arm, modelname: arm}\n")
    write(tmp_path / "models/arm2.yml", textwrap.dedent("""\
        model:
          robotname: arm2
          modelname: arm2
          input_models: {a: {derived_base: arm.yml}}
          assemble: {model: a, name_editing: {prefix: x_}}
        """))
    write(tmp_path / "ci/pipeline.yml", "pipeline:\n  root: ..\n  model_definitions: [../models/arm2.yml, "
          "../models/arm.yml]\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = run_json(tmp_path / "ci/pipeline.yml", cache=tmp_path / "cache", cwd=elsewhere)
    assert run.returncode == 0, run.stderr
    assert run.states() == {"arm2": "ok", "arm": "ok"}
    assert (tmp_path / "build/arm2/urdf/arm2.urdf").is_file()
    assert list(elsewhere.iterdir()) == []


def test_check_applies_the_pipeline_defaults(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", _model("m"))
    write(tmp_path / "pipeline.yml", """
        pipeline:
          model_definitions: [m.yml]
          default_export_config:
            - {type: urdf, mesh_format: stl, filename_suffix: 7}
        """)
    done = mpc("check", "pipeline.yml", cwd=tmp_path)
    assert done.returncode == 1
    assert "pipeline.yml:4:55: error[E0203]: 'filename_suffix' must be a string, got int '7'" in done.stderr


def test_a_modelname_that_cannot_name_a_folder(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", _model("robots/arm"))
    write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [m.yml]\n")
    plan = load_plan(tmp_path / "pipeline.yml", Sink())
    assert plan is not None
    [diag] = plan.models["robots/arm"].diagnostics
    assert (diag.code, diag.message, diag.hint) == (
        "E0612", "modelname 'robots/arm' cannot name an output folder",
        "a modelname is a folder name: no '/', and not starting with '.'")


def test_check_reports_what_only_the_whole_pipeline_shows(tmp_path: Path) -> None:
    write(tmp_path / "one.yml", _model("same"))
    write(tmp_path / "two.yml", _model("same"))
    write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [one.yml, two.yml]\n")
    done = mpc("check", "pipeline.yml", cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == ("pipeline.yml:3:32: error[E0610]: model definitions 'one.yml' and "
                                           "'two.yml' both build model 'same'")


def test_check_of_a_definition_imports_nothing_of_the_pipeline(tmp_path: Path) -> None:
    """`mpc check` stays fast: the pipeline runner (multiprocessing, rich) loads only for pipelines."""
    import subprocess
    import sys

    write(tmp_path / "m.yml", _model("m"))
    code = ("import sys\nfrom mpc.cli.main import main\nstatus = main(['check', sys.argv[1]])\n"
            "print(status, sorted(m for m in sys.modules if m.startswith('mpc.pipeline') "
            "or m in ('multiprocessing', 'rich')))")
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path / "m.yml")], capture_output=True,
                          text=True, check=True)
    assert done.stdout == "0 []\n"


def test_check_reports_unusable_entries_once_and_reads_none_of_them(tmp_path: Path) -> None:
    write(tmp_path / "outside.yml", "not: [a definition\n")  # would be E0102 if it were read
    write(tmp_path / "p/m.yml", _model("m"))
    (tmp_path / "p/folder").mkdir()
    write(tmp_path / "p/pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [m.yml, folder, nope.yml, "
                                       "../outside.yml]\n")
    done = mpc("check", "pipeline.yml", cwd=tmp_path / "p")
    assert done.returncode == 1
    assert [line for line in done.stderr.splitlines() if "error" in line] == [
        "pipeline.yml:3:30: error[E0601]: model definition 'folder' is a folder, not a file",
        "pipeline.yml:3:38: error[E0601]: model definition 'nope.yml' does not exist",
        f"pipeline.yml:3:48: error[E0641]: model definition '../outside.yml' is outside the workspace root "
        f"'{tmp_path / 'p'}'",
        "3 errors in 1 file"]
