"""The cache of `mpc run`: a model is rebuilt when anything its build reads changes (its
definition, the defaults file it inherits, its URDF and meshes, its derived_base parent, the
pipeline's defaults, mpc itself, `--package`, `--werror`) and only then: not for a touched
file, another working folder, or the same project checked out at another path.

The project: `base` (a defaults file gives it a copy of example-robot-data's double pendulum,
found through `--package`), its dependant `child`, and `other` (an installed URDF).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from mpc.core.packages import PackageResolver
from mpc.pipeline.fingerprint import PACKAGE, deps_current, package_entry
from tests.conftest import ERD, write
from tests.pipeline.helpers import run_json

DOUBLE_PENDULUM = "double_pendulum_description"
ALL = {"base", "child", "other"}


def _write(folder: Path) -> None:
    shutil.copytree(ERD / DOUBLE_PENDULUM, folder / "erd/robots" / DOUBLE_PENDULUM)
    write(folder / "models/common.yml", f"""
        default_model:
          input_models:
            b: {{basefile: "package://example-robot-data/robots/{DOUBLE_PENDULUM}/urdf/double_pendulum.urdf"}}
          assemble: {{model: b}}
        """)
    write(folder / "models/base.yml", "defaults: common.yml\nmodel: {robotname: base, modelname: base}\n")
    write(folder / "models/child.yml", """
        model:
          robotname: child
          modelname: child
          input_models: {a: {derived_base: base.yml}}
          assemble: {model: a, name_editing: {prefix: c_}}
        """)
    write(folder / "models/other.yml", f"""
        model:
          robotname: other
          modelname: other
          input_models: {{b: {{basefile: "{ERD / DOUBLE_PENDULUM}/urdf/double_pendulum_simple.urdf"}}}}
          assemble: {{model: b}}
        """)
    write(folder / "ci/pipeline.yml", """
        pipeline:
          root: ..
          model_definitions: [../models/child.yml, ../models/other.yml, ../models/base.yml]
          default_export_config:
            - {type: urdf, mesh_format: input_type}
        """)


def _run(folder: Path, *args: str, cwd: Path | None = None) -> dict[str, str]:
    """The states of a run of the project in `folder` (with its own copy of the package)."""
    run = run_json(folder / "ci/pipeline.yml", "--package", f"example-robot-data={folder / 'erd'}", *args,
                   cache=folder.parent / "cache", cwd=cwd)
    assert run.returncode == 0, run.stderr
    return run.states()


def _rebuilt(states: dict[str, str]) -> set[str]:
    assert set(states.values()) <= {"ok", "cached"}, states
    return {name for name, state in states.items() if state == "ok"}


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("cache") / "project"
    _write(folder)
    assert _rebuilt(_run(folder)) == ALL
    assert _rebuilt(_run(folder)) == set()
    return folder


@pytest.fixture
def project(built: Path, tmp_path: Path) -> Path:
    """A copy of the built project, at the same path each time so its cache still holds."""
    shutil.copytree(built, tmp_path / "project", symlinks=True)
    here = tmp_path / "project"
    # The state names files inside the root relative to it, so the copy is cached as it is.
    assert _rebuilt(_run(here)) == set()
    return here


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


URDF = f"erd/robots/{DOUBLE_PENDULUM}/urdf/double_pendulum.urdf"

CHANGES = {
    "the definition": (lambda p: _edit(p / "models/base.yml", "robotname: base,", "robotname: base2,"),
                       {"base", "child"}),
    "the defaults file it inherits": (lambda p: _edit(p / "models/common.yml", "assemble: {model: b}",
                                                      "assemble: {model: b, name_editing: {prefix: d_}}"),
                                      {"base", "child"}),
    "the input URDF": (lambda p: _edit(p / URDF, 'value="0.10159"', 'value="0.2"'), {"base", "child"}),
    "a mesh of the URDF": (lambda p: shutil.copyfile(p / f"erd/robots/{DOUBLE_PENDULUM}/meshes/link2.stl",
                                                     p / f"erd/robots/{DOUBLE_PENDULUM}/meshes/link1.stl"),
                           {"base", "child"}),
    "the derived_base child's own definition": (lambda p: _edit(p / "models/child.yml", "prefix: c_",
                                                                "prefix: k_"), {"child"}),
    "the pipeline's defaults": (lambda p: _edit(p / "ci/pipeline.yml", "mesh_format: input_type",
                                                "mesh_format: stl"), ALL),
}


@pytest.mark.parametrize("change", CHANGES)
def test_a_change_rebuilds_exactly_the_models_that_read_it(project: Path, change: str) -> None:
    apply, expected = CHANGES[change]
    apply(project)
    assert _rebuilt(_run(project)) == expected
    assert _rebuilt(_run(project)) == set()


def test_a_mesh_is_an_input_the_state_records(project: Path) -> None:
    import json

    state = json.loads((project / "build/.mpc/state/base.json").read_text())
    names = [entry[0] for entry in state["deps"]]
    assert f"erd/robots/{DOUBLE_PENDULUM}/meshes/link1.stl" in names
    assert "models/common.yml" in names and URDF in names


def test_package_folders_and_werror_are_part_of_the_fingerprint(project: Path, tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    shutil.copytree(project / "erd", elsewhere)
    states = run_json(project / "ci/pipeline.yml", "--package", f"example-robot-data={elsewhere}",
                      cache=tmp_path / "cache").states()
    assert _rebuilt(states) == ALL
    assert _rebuilt(_run(project)) == ALL  # back to the project's own copy
    assert _rebuilt(_run(project, "--werror")) == ALL
    assert _rebuilt(_run(project, "--werror")) == set()


def test_where_ros_package_path_finds_a_package_is_part_of_the_fingerprint(project: Path,
                                                                          tmp_path: Path) -> None:
    """Another copy of a package named by ROS_PACKAGE_PATH rebuilds the models that found it
    there, though no file they read changed; the same copy again rebuilds nothing."""
    copies = {}
    for name in ("a", "b"):
        copies[name] = tmp_path / name
        shutil.copytree(project / "erd", copies[name] / "example-robot-data")
    pipeline, cache = project / "ci/pipeline.yml", tmp_path / "cache"

    def rebuilt(ros_package_path: str) -> set[str]:
        run = run_json(pipeline, cache=cache, environ={"ROS_PACKAGE_PATH": ros_package_path,
                                                       "AMENT_PREFIX_PATH": ""})
        assert run.returncode == 0, run.stderr
        return _rebuilt(run.states())

    assert rebuilt(str(copies["a"])) == ALL  # no --package: another fingerprint
    assert rebuilt(str(copies["a"])) == set()
    assert rebuilt(str(copies["b"])) == {"base", "child"}
    assert rebuilt(str(copies["b"])) == set()
    state = json.loads((project / "build/.mpc/state/base.json").read_text())
    found = str(copies["b"] / "example-robot-data")
    assert sorted(d for d in state["deps"] if d[1] == PACKAGE) == [  # from the definition, the URDF
        [f"package://example-robot-data\0{found}/robots/{DOUBLE_PENDULUM}/urdf", PACKAGE, 0, found],
        ["package://example-robot-data\0models", PACKAGE, 0, found]]


def test_where_a_package_xml_name_finds_a_package_is_part_of_the_fingerprint(project: Path,
                                                                            tmp_path: Path) -> None:
    """A package found by its package.xml's name in a crawled ROS_PACKAGE_PATH (a clone under
    another folder name) is recorded where it was found; once that package.xml names another
    package, the copy found next rebuilds the models that used it."""
    clone = tmp_path / "a/group/erd-master"
    shutil.copytree(project / "erd", clone)
    write(clone / "package.xml", "<package format='3'><name>example-robot-data</name></package>\n")
    shutil.copytree(project / "erd", tmp_path / "b/example-robot-data")
    pipeline, cache = project / "ci/pipeline.yml", tmp_path / "cache"

    def rebuilt() -> set[str]:
        run = run_json(pipeline, cache=cache, environ={
            "ROS_PACKAGE_PATH": f"{tmp_path / 'a'}{os.pathsep}{tmp_path / 'b'}", "AMENT_PREFIX_PATH": ""})
        assert run.returncode == 0, run.stderr
        return _rebuilt(run.states())

    def found() -> set[str]:
        state = json.loads((project / "build/.mpc/state/base.json").read_text())
        return {d[3] for d in state["deps"] if d[1] == PACKAGE}

    assert rebuilt() == ALL
    assert rebuilt() == set()
    assert found() == {str(clone)}
    _edit(clone / "package.xml", "<name>example-robot-data</name>", "<name>erd_fork</name>")
    assert rebuilt() == {"base", "child"}
    assert found() == {str(tmp_path / "b/example-robot-data")}


def test_touching_every_file_or_running_from_another_folder_rebuilds_nothing(project: Path,
                                                                            tmp_path: Path) -> None:
    for path in project.rglob("*"):
        if path.is_file() and "build" not in path.relative_to(project).parts:
            os.utime(path)
    assert _rebuilt(_run(project)) == set()
    (tmp_path / "somewhere").mkdir()
    assert _rebuilt(_run(project, cwd=tmp_path / "somewhere")) == set()
    assert _rebuilt(_run(project, cwd=project / "models")) == set()


def test_a_checkout_at_another_path_keeps_its_cache_and_sees_its_own_files(project: Path,
                                                                           tmp_path: Path) -> None:
    """A clone elsewhere (CI, a colleague) is cached as the original; a file changed in it
    rebuilds its models even though the original, unchanged, is still there."""
    moved = tmp_path / "moved" / "checkout"
    shutil.copytree(project, moved, symlinks=True)
    assert _rebuilt(_run(moved)) == set()
    _edit(moved / URDF, 'value="0.10159"', 'value="0.2"')
    assert _rebuilt(_run(moved)) == {"base", "child"}
    assert _rebuilt(_run(project)) == set()


def test_a_new_mpc_version_rebuilds_everything(project: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from mpc.core.diagnostics import Sink
    from mpc.pipeline import freshness, runner
    from mpc.pipeline.plan import load_plan
    from mpc.pipeline.progress import Quiet

    monkeypatch.setenv("MPC_CACHE_DIR", str(project.parent / "cache"))
    options = runner.RunOptions(jobs=1, package_map={"example-robot-data": project / "erd"})

    def states() -> dict[str, str]:
        plan = load_plan(project / "ci/pipeline.yml", Sink())
        assert plan is not None
        status = runner.Runner(plan, options, Quiet()).run()
        return {name: m.stages["compile"].state for name, m in status.models.items()}

    assert _rebuilt(states()) == set()
    monkeypatch.setattr(freshness, "source_version", lambda: "99.0+0123456789abcdef")
    assert _rebuilt(states()) == ALL
    assert _rebuilt(states()) == set()


def test_the_installed_package_is_named_absolutely(project: Path) -> None:
    """Files outside the root (installed robot packages) keep their absolute names."""
    import json

    state = json.loads((project / "build/.mpc/state/other.json").read_text())
    names = [entry[0] for entry in state["deps"]]
    assert f"{ERD / DOUBLE_PENDULUM}/urdf/double_pendulum_simple.urdf" in names
    assert "models/other.yml" in names


def test_mpc_version_hashes_the_sources_of_mpc_and_nothing_else() -> None:
    """In a checkout, tests/ lies next to compiler/: editing a test must not rebuild models."""
    from mpc.core.version import source_files

    names = {name for name, _ in source_files()}
    assert {"compiler/driver.py", "pipeline/runner.py", "grammar/expr.lark", "ir/robot.py",
            "backends/urdf.py"} <= names
    packages = {name.split("/")[0] for name in names}
    assert packages == {"backends", "checks", "cli", "compiler", "core", "deploy", "grammar", "ir",
                        "lsp", "pipeline"}


def test_a_package_not_found_then_found_makes_the_deps_stale(tmp_path: Path) -> None:
    """A build that failed because a package was not found is built again once it is found
    (its failure is not "unchanged since it failed")."""
    (tmp_path / "share/nopkg").mkdir(parents=True)
    deps = [package_entry("nopkg", str(tmp_path / "models"), None, tmp_path)]
    assert deps == [["package://nopkg\0models", PACKAGE, 0, "missing"]]
    nowhere = PackageResolver(search_path=[])
    assert deps_current(deps, tmp_path, nowhere) == deps
    found = PackageResolver(search_path=[tmp_path / "share"])
    assert deps_current(deps, tmp_path, found) is None
    assert package_entry("nopkg", "", str(tmp_path / "share/nopkg"), tmp_path) == [
        "package://nopkg\0", PACKAGE, 0, "share/nopkg"]
