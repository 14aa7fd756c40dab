"""Bad input to `mpc run` from the command line: a clear diagnostic (with file:line:col where
there is a file), exit status 1 (bad input) or 2 (bad command line), never an internal error
(3), and the previous outputs kept."""

from __future__ import annotations

import json
import shutil
import textwrap
from pathlib import Path

import pytest

from tests.conftest import ERD, write
from tests.pipeline.helpers import mpc, run_json

PENDULUM = ERD / "double_pendulum_description/urdf/double_pendulum_simple.urdf"


def _model(name: str, base: str = f'basefile: "{PENDULUM}"') -> str:
    return f"model:\n  robotname: {name}\n  modelname: {name}\n  input_models: {{b: {{{base}}}}}\n" \
           "  assemble: {model: b}\n"


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A pipeline of one model (`p`), built once: the previous output the tests keep."""
    folder = tmp_path_factory.mktemp("built")
    write(folder / "p.yml", _model("p"))
    write(folder / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [p.yml]\n")
    first = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert first.returncode == 0, first.stderr
    return folder


def _copy(built: Path, to: Path) -> Path:
    shutil.copytree(built, to, symlinks=True)
    return to


def _urdf(folder: Path) -> bytes:
    return (folder / "build/p/urdf/p.urdf").read_bytes()


PIPELINES = {
    "malformed YAML": ("pipeline:\n  model_definitions: [p.yml\n",
                       "pipeline.yml:3:1: error[E0102]: malformed YAML: expected ',' or ']', "
                       "but got '<stream end>'"),
    "an unknown key": ("pipeline:\n  root: .\n  model_definitons: [p.yml]\n",
                       "pipeline.yml:3:3: error[E0201]: unknown key 'model_definitons' in pipeline; "
                       "did you mean 'model_definitions'?"),
    "an empty list": ("pipeline:\n  root: .\n  model_definitions: []\n",
                      "pipeline.yml:3:22: error[E0203]: 'model_definitions' must not be empty"),
    "a root that does not exist": ("pipeline:\n  root: nowhere\n  model_definitions: [p.yml]\n",
                                   "pipeline.yml:2:9: error[E0640]: the workspace root '{folder}/nowhere' "
                                   "does not exist"),
    "a root with an unset variable": ("pipeline:\n  root: ${MPC_NOT_SET}/x\n  model_definitions: [p.yml]\n",
                                      "pipeline.yml:2:9: error[E0640]: the workspace root "
                                      "'{folder}/${{MPC_NOT_SET}}/x' does not exist\n"
                                      " 2 |   root: ${{MPC_NOT_SET}}/x\n"
                                      "   |         ^^^^^^^^^^^^^^^^\n"
                                      "  hint: the environment variable MPC_NOT_SET is not set"),
    "a root that is not a path": ('pipeline:\n  root: "a\\0b"\n  model_definitions: [p.yml]\n',
                                  "pipeline.yml:2:9: error[E0106]: a NUL character in a string: "
                                  "no file, link, joint or other name can hold one"),
    "an entry that is not a path": ('pipeline:\n  root: .\n  model_definitions: [p.yml, "q\\0.yml"]\n',
                                    "pipeline.yml:3:30: error[E0106]: a NUL character in a string: "
                                    "no file, link, joint or other name can hold one"),
    "a root that is a file": ("pipeline:\n  root: p.yml\n  model_definitions: [p.yml]\n",
                              "pipeline.yml:2:9: error[E0640]: the workspace root '{folder}/p.yml' "
                              "is not a folder"),
}


@pytest.mark.parametrize("case", PIPELINES)
def test_an_unusable_pipeline_file_is_reported_and_nothing_is_touched(built: Path, tmp_path: Path,
                                                                       case: str) -> None:
    folder = _copy(built, tmp_path / "p")
    text, message = PIPELINES[case]
    before = _urdf(folder)
    (folder / "pipeline.yml").write_text(text)
    done = mpc("run", "pipeline.yml", cwd=folder)
    assert done.returncode == 1, done.stderr
    assert message.format(folder=folder) in done.stderr
    assert "internal error" not in done.stderr
    assert _urdf(folder) == before
    assert not (folder / "nowhere").exists()  # a root that does not exist is not made


MODELS = {
    "a missing definition": ("[p.yml, nope.yml]", "nope",
                             "pipeline.yml:3:30: error[E0601]: model definition 'nope.yml' does not exist"),
    "a definition that is a folder": ("[p.yml, folder]", "folder",
                                      "pipeline.yml:3:30: error[E0601]: model definition 'folder' is a "
                                      "folder, not a file"),
    "a definition outside the root": ("[p.yml, ../outside.yml]", "outside",
                                      "pipeline.yml:3:30: error[E0641]: model definition '../outside.yml' is "
                                      "outside the workspace root '{folder}'"),
}


@pytest.mark.parametrize("case", MODELS)
def test_a_bad_entry_fails_only_its_model(built: Path, tmp_path: Path, case: str) -> None:
    folder = _copy(built, tmp_path / "p")
    (folder / "folder").mkdir()
    write(tmp_path / "outside.yml", _model("outside"))
    entries, name, message = MODELS[case]
    write(folder / "pipeline.yml", f"pipeline:\n  root: .\n  model_definitions: {entries}\n")
    run = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert run.returncode == 1
    assert message.format(folder=folder) in run.stderr
    assert run.states() == {"p": "cached", name: "failed"}
    assert not (folder / "build" / name).exists()


def test_duplicate_entries_are_built_once_with_a_warning(built: Path, tmp_path: Path) -> None:
    folder = _copy(built, tmp_path / "p")
    write(folder / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [p.yml, ./p.yml]\n")
    run = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert run.returncode == 0, run.stderr
    assert "pipeline.yml:3:30: warning[W0611]: model definition './p.yml' is listed twice; it is built once" \
        in run.stderr
    assert run.states() == {"p": "cached"}


@pytest.mark.parametrize(("args", "message"), [
    (["-j", "0"], "mpc run: error: -j needs at least 1"),
    (["-j", "-1"], "mpc run: error: -j needs at least 1"),
    (["-j", "two"], "argument -j/--jobs: invalid int value: 'two'"),
    (["--only", ""], "mpc run: error: --only: no model '' in 'pipeline.yml'"),
    (["--only", "."], "mpc run: error: --only: no model '.' in 'pipeline.yml'"),
    (["--only", "q"], "mpc run: error: --only: no model 'q' in 'pipeline.yml'\n"),
    (["--only"], "argument --only: expected at least one argument"),
    (["--stages", ""], "mpc run: error: --stages names no stage"),
    (["--stages", " , ,"], "mpc run: error: --stages names no stage"),
    (["--stages", "compile test"], "mpc run: error: unknown stage 'compile test'; did you mean 'compile'?"),
])
def test_a_bad_command_line_is_exit_status_2(built: Path, args: list[str], message: str) -> None:
    done = mpc("run", "pipeline.yml", *args, cwd=built)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr


def test_stages_with_spaces_and_empty_items_are_read_as_the_names(built: Path) -> None:
    run = run_json(built / "pipeline.yml", "--stages", " compile, ,compile ", cache=built / "cache")
    assert run.returncode == 0, run.stderr
    assert run.status["stages"] == ["compile"]
    assert run.states() == {"p": "cached"}


def test_a_build_folder_that_is_a_file_is_an_error(built: Path, tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    done = mpc("run", built / "pipeline.yml", "-o", tmp_path / "file")
    assert done.returncode == 1
    assert done.stderr == (f"mpc run: error: cannot use the build folder '{tmp_path}/file' (Not a directory: "
                           f"'{tmp_path}/file/.mpc'); nothing was built\n")


@pytest.mark.parametrize(("file", "message", "table"), [
    ("lock", "cannot use the build folder '{build}' (Is a directory: '{build}/.mpc/lock'); "
             "nothing was built", ""),
    ("status.json", "cannot write the status file '{build}/.mpc/status.json' (Is a directory)",
     "1 model: 1 cached"),
])
def test_a_folder_where_the_run_writes_a_file_is_an_error(built: Path, tmp_path: Path, file: str,
                                                           message: str, table: str) -> None:
    folder = _copy(built, tmp_path / "p")
    (folder / "build/.mpc" / file).unlink()
    (folder / "build/.mpc" / file).mkdir()
    done = mpc("run", "pipeline.yml", cwd=folder)
    assert done.returncode == 1
    assert done.stderr == f"mpc run: error: {message.format(build=folder / 'build')}\n"
    assert table in done.stdout


# Tests run as root, where permissions do not stop writes; a folder where the state file
# should be stops its write as a read-only file does for a user.
def test_a_state_file_that_cannot_be_written_fails_the_model_and_keeps_its_output(built: Path,
                                                                                  tmp_path: Path) -> None:
    folder = _copy(built, tmp_path / "p")
    before = _urdf(folder)
    state = folder / "build/.mpc/state/p.json"
    state.unlink()
    state.mkdir()
    (folder / "p.yml").write_text(_model("p").replace("assemble: {model: b}", "assemble: {model: b, "
                                                                              "name_editing: {prefix: x_}}"))
    run = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert run.returncode == 1
    assert run.state("p") == "failed"
    assert (f"error[E0642]: cannot write the build of model 'p' (Is a directory: '{state}'); its previous "
            "output is unchanged") in run.stderr
    assert _urdf(folder) == before
    assert list((folder / "build/.mpc/staging").iterdir()) == []


def test_a_staging_folder_that_cannot_be_made_fails_the_model(built: Path, tmp_path: Path) -> None:
    folder = _copy(built, tmp_path / "p")
    shutil.rmtree(folder / "build/.mpc/staging", ignore_errors=True)
    (folder / "build/.mpc/staging").write_text("")
    run = run_json(folder / "pipeline.yml", "--force", cache=folder / "cache")
    assert run.returncode == 1
    assert (f"error[E0642]: cannot write the build of model 'p' (Not a directory: "
            f"'{folder}/build/.mpc/staging/p')") in run.stderr
    assert _urdf(folder) == _urdf(built)


def _state(folder: Path) -> dict:
    return json.loads((folder / "build/.mpc/state/p.json").read_text())


CORRUPT = {
    "truncated": lambda good: json.dumps(good)[:40],
    "not a mapping": lambda good: "[1, 2]",
    "deps of the wrong shape": lambda good: json.dumps({**good, "deps": [[1, 2]]}),
    "deps not a list": lambda good: json.dumps({**good, "deps": 5}),
    "a dep without a path": lambda good: json.dumps({**good, "deps": [[None, 1, 1, "x"]]}),
    "stages not a mapping": lambda good: json.dumps({**good, "stages": 5}),
    "a stage not a mapping": lambda good: json.dumps({**good, "stages": {"compile": 5}}),
    "a fingerprint not a string": lambda good: json.dumps({**good, "fingerprint": 5}),
    "a failure with bad deps": lambda good: json.dumps({**good, "failure": {"pre": good["pre"], "deps": 5}}),
    "a failure with a bad summary": lambda good: json.dumps(
        {**good, "failure": {"pre": good["pre"], "deps": [], "summary": 3, "diagnostics": []}}),
    "nested 5000 deep": lambda good: json.dumps({**good, "deps": []})[:-1] + ', "x": '
                                     + "[" * 5000 + "]" * 5000 + "}",
    "a number of 4000 digits": lambda good: json.dumps({**good, "x": 10 ** 4000 - 1}),
    "a failure with bad diagnostics": lambda good: json.dumps(
        {**good, "failure": {"pre": good["pre"], "deps": [], "summary": "x", "diagnostics": [{"a": 1}]}}),
}


@pytest.mark.parametrize("case", CORRUPT)
def test_a_corrupt_state_file_rebuilds_the_model_with_a_warning(built: Path, tmp_path: Path,
                                                                case: str) -> None:
    folder = _copy(built, tmp_path / "p")
    state = folder / "build/.mpc/state/p.json"
    damaged = CORRUPT[case](_state(folder))
    state.write_text(damaged)
    run = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert run.returncode == 0, run.stderr
    assert run.state("p") == "ok"
    # said at the damaged file, kept beside the new state, and quoted from it (issue 35.8)
    warning = f"{state}.unusable:1:"
    assert f"{warning}" in run.stderr and "warning[W0640]: the state of model 'p' from an earlier " \
        "run is unusable (" in run.stderr
    assert "the model is built again; it is kept as p.json.unusable" in run.stderr
    assert f" 1 | {damaged[:30]}" in run.stderr
    assert (folder / "build/.mpc/state/p.json.unusable").read_text() == damaged
    assert _urdf(folder) == _urdf(built)
    again = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert (again.state("p"), again.stderr) == ("cached", "")


def test_a_corrupt_status_file_is_replaced(built: Path, tmp_path: Path) -> None:
    folder = _copy(built, tmp_path / "p")
    (folder / "build/.mpc/status.json").write_text('{"models": [1, ')
    run = run_json(folder / "pipeline.yml", cache=folder / "cache")
    assert (run.returncode, run.states()) == (0, {"p": "cached"})


def test_a_derived_base_cycle_across_three_files_fails_them_and_their_dependant(tmp_path: Path) -> None:
    for name, parent in (("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")):
        write(tmp_path / f"{name}.yml", _model(name, base=f"derived_base: {parent}.yml"))
    write(tmp_path / "p.yml", _model("p"))
    write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: "
                                     "[a.yml, b.yml, c.yml, d.yml, p.yml]\n")
    run = run_json(tmp_path / "pipeline.yml", cache=tmp_path / "cache")
    assert run.returncode == 1
    assert run.states() == {"a": "failed", "b": "failed", "c": "failed", "d": "skipped", "p": "ok"}
    for name, parent in (("a", "b"), ("b", "c"), ("c", "a")):
        assert (f"{name}.yml:4:36: error[E0611]: derived_base cycle: a.yml → b.yml → c.yml → a.yml\n"
                f" 4 |   input_models: {{b: {{derived_base: {parent}.yml}}}}") in run.stderr
    assert run.status["models"]["d"]["stages"]["compile"]["reason"] == "derived_base 'a' failed"


@pytest.mark.parametrize("change", ["edited", "broken", "deleted"])
def test_a_definition_that_changes_between_plan_and_build(built: Path, tmp_path: Path, change: str,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """The runner plans from the file as it was; the worker builds the file as it is."""
    from mpc.core.diagnostics import Sink
    from mpc.pipeline.plan import load_plan
    from mpc.pipeline.progress import Quiet
    from mpc.pipeline.runner import Runner, RunOptions

    folder = _copy(built, tmp_path / "p")
    monkeypatch.setenv("MPC_CACHE_DIR", str(folder / "cache"))
    definition = folder / "p.yml"
    definition.write_text(_model("p").replace("assemble: {model: b}", "assemble: {model: b, "
                                                                      "name_editing: {prefix: x_}}"))
    plan = load_plan(folder / "pipeline.yml", Sink())
    assert plan is not None
    if change == "edited":
        definition.write_text(_model("p").replace("assemble: {model: b}", "assemble: {model: b, "
                                                                          "name_editing: {prefix: y_}}"))
    elif change == "broken":
        definition.write_text(textwrap.dedent("model: {robotname: p, modelname: p, assemble: [\n"))
    else:
        definition.unlink()
    before = _urdf(folder)
    status = Runner(plan, RunOptions(jobs=1), Quiet()).run()
    record = status.models["p"].stages["compile"]
    codes = [d.code for d in record.diagnostics]
    if change == "edited":
        assert record.state == "ok"
        assert b'name="y_' in _urdf(folder)
        assert b'name="x_' not in _urdf(folder)
        # The state describes what was built: the next runs rebuild once to match the plan, then cache.
        states = [run_json(folder / "pipeline.yml", cache=folder / "cache").state("p") for _ in range(2)]
        assert states == ["ok", "cached"]
    else:
        assert (record.state, status.exit_status()) == ("failed", 1)
        assert "E0614" not in codes and codes
        assert _urdf(folder) == before
