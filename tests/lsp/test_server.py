"""`mpc lsp` driven over stdio by a plain LSP client (tests/lsp/client.py): diagnostics as
`mpc check` gives them, completion of names after a rename, hover, go to definition into the
URDF, rename, code actions, symbols, a defaults file changing its users' diagnostics.

One server serves the whole module (each test opens files of its own); the arm of specs/examples
is the input model.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from mpc.cli.check import check_file
from mpc.compiler.options import Options
from mpc.core.diagnostics import Sink
from tests.lsp.client import Client
from tests.lsp.definitions import EXPORT, HEAD

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"

DEFINITION = HEAD + """\
  frames:
    upper:
      name_editing:
        suffix: _arm
    tool:
      parent: lower
      xyz: [0, 0, 0.1]
  joints:
    shoulder:
      min: ["deg", 45]
    elbo:
      damping: 0.5
  collisions:
    upper_arm:
      shape: box
  poses:
    init:
      shoulder: [deg, 30]
""" + EXPORT


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    work = tmp_path_factory.mktemp("lsp")
    for name in ("arm.urdf", "arm.urdf.xacro", "arm_segment.xacro"):
        shutil.copy(EXAMPLES / name, work / name)
    shutil.copytree(EXAMPLES / "meshes", work / "meshes")
    return work


@pytest.fixture(scope="module")
def server(folder: Path) -> Client:
    client = Client(env={**os.environ, "MPC_CACHE_DIR": str(folder / "cache")}, cwd=folder)
    client.initialize(folder)
    yield client
    assert client.close() == 0  # shutdown and exit end the server cleanly


def opened(server: Client, path: Path, text: str) -> tuple[str, list[dict]]:
    path.write_text(text, encoding="utf-8")
    uri = server.open(path)
    return uri, server.diagnostics(uri, 1)


def test_capabilities(server: Client) -> None:
    for provider in ("completionProvider", "hoverProvider", "definitionProvider", "renameProvider",
                     "codeActionProvider", "documentSymbolProvider"):
        assert server.capabilities[provider], provider


def test_diagnostics_are_mpc_checks_at_their_range(server: Client, folder: Path) -> None:
    path = folder / "check.yml"
    _, diagnostics = opened(server, path, DEFINITION)
    sink = Sink()
    check_file(path, sink, Options())
    assert [(d["code"], d["message"].split("\n")[0]) for d in diagnostics] == \
        [(d.code, d.message) for d in sink.diagnostics]
    elbo = next(d for d in diagnostics if "'elbo'" in d["message"])
    assert elbo["range"] == {"start": {"line": 18, "character": 4}, "end": {"line": 18, "character": 8}}
    assert elbo["message"] == ("joints refers to unknown joint 'elbo'; did you mean 'elbow'?\n"
                               "hint: there are: elbow, tool, shoulder")
    assert elbo["severity"] == 1 and elbo["source"] == "mpc"


def test_a_line_break_of_yaml_alone_leaves_diagnostics_on_the_editor_s_lines(server: Client,
                                                                             folder: Path) -> None:
    """U+2028 breaks a line for PyYAML (YAML 1.1) but not in the editor: the unknown joint
    'elbo' is on the editor's line 19, one below where it is without the comment."""
    _, diagnostics = opened(server, folder / "separator.yml", "# a note\u2028\n" + DEFINITION)
    elbo = next(d for d in diagnostics if "'elbo'" in d["message"])
    assert elbo["range"] == {"start": {"line": 19, "character": 4}, "end": {"line": 19, "character": 8}}


def test_a_missing_mesh_file_is_reported_as_mpc_check_reports_it(server: Client, tmp_path: Path) -> None:
    alone = tmp_path  # the arm without its meshes folder
    shutil.copy(EXAMPLES / "arm.urdf", alone / "arm.urdf")
    path = alone / "arm.yml"
    _, diagnostics = opened(server, path, DEFINITION.replace("elbo:", "elbow:"))
    sink = Sink()
    check_file(path, sink, Options())
    message = f"mesh file '{alone / 'meshes/tetra.stl'}' of a visual of link 'base' does not exist"
    assert [(d.code, d.message) for d in sink.diagnostics] == [("E0602", message)]
    # the problem is in arm.urdf: shown on the line that reads it, with its own file and line
    (diagnostic,) = diagnostics
    assert (diagnostic["code"], diagnostic["message"]) == ("E0602", f"arm.urdf:10: {message}")
    assert diagnostic["range"] == {"start": {"line": 5, "character": 16}, "end": {"line": 5, "character": 24}}
    assert diagnostic["relatedInformation"] == [{"message": message, "location": {
        "uri": (alone / "arm.urdf").as_uri(),
        "range": {"start": {"line": 9, "character": 32}, "end": {"line": 9, "character": 48}}}}]


def test_change_is_checked_again(server: Client, folder: Path) -> None:
    uri, diagnostics = opened(server, folder / "change.yml", DEFINITION)
    assert [d["code"] for d in diagnostics] == ["E0310"]
    server.change(uri, 2, DEFINITION.replace("elbo:", "elbow:"))
    assert server.diagnostics(uri, 2) == []
    server.change(uri, 3, DEFINITION.replace("parent: lower", "parent: lowr"))
    (diagnostic,) = [d for d in server.diagnostics(uri, 3) if "lowr" in d["message"]]
    assert diagnostic["range"]["start"] == {"line": 13, "character": 14}
    # a two-line problem: the other line is related information
    server.change(uri, 4, DEFINITION.replace("  input_models:\n", "  robotname: b\n  input_models:\n"))
    (duplicate,) = server.diagnostics(uri, 4)
    assert (duplicate["code"], duplicate["message"]) == ("E0103", "duplicate key 'robotname'")
    assert duplicate["range"] == {"start": {"line": 3, "character": 2}, "end": {"line": 3, "character": 11}}
    assert duplicate["relatedInformation"] == [{"message": "first written here", "location": {
        "uri": uri, "range": {"start": {"line": 1, "character": 2}, "end": {"line": 1, "character": 11}}}}]


def test_an_incremental_change(server: Client, folder: Path) -> None:
    """The server syncs incrementally (textDocumentSync.change 2): a change may give a range."""
    assert server.capabilities["textDocumentSync"]["change"] == 2
    uri, diagnostics = opened(server, folder / "incremental.yml", DEFINITION)
    assert [d["range"]["end"] for d in diagnostics] == [{"line": 18, "character": 8}]  # after 'elbo'
    after = {"line": 18, "character": 8}
    server.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 2},
                                             "contentChanges": [{"range": {"start": after, "end": after},
                                                                 "text": "w"}]})
    assert server.diagnostics(uri, 2) == []


def test_code_action_applies_the_did_you_mean(server: Client, folder: Path) -> None:
    uri, diagnostics = opened(server, folder / "action.yml", DEFINITION)
    (action,) = server.request("textDocument/codeAction", {
        "textDocument": {"uri": uri}, "range": diagnostics[0]["range"],
        "context": {"diagnostics": diagnostics}})
    assert action["title"] == "Change to 'elbow'" and action["kind"] == "quickfix"
    assert action["edit"]["changes"][uri] == [{"range": diagnostics[0]["range"], "newText": "elbow"}]


def labels(server: Client, uri: str, line: int, character: int) -> list[str]:
    answer = server.request("textDocument/completion", server.at(uri, line, character))
    return [item["label"] for item in answer["items"]]


def test_completion_of_names_as_they_are_at_the_cursor(server: Client, folder: Path) -> None:
    uri, _ = opened(server, folder / "complete.yml", DEFINITION)
    # collisions run after the frames' renaming: the link is upper_arm there
    text = DEFINITION.replace("      shape: box\n", "      shape: box\n    \n")
    server.change(uri, 2, text)
    after = labels(server, uri, 23, 4)
    assert {"upper_arm", "base", "lower", "tool"} <= set(after) and "upper" not in after
    # a new frame's parent is looked up before the renaming
    assert labels(server, uri, 13, 14) == ["base", "lower", "upper"]
    # joint names in a pose; keys of a joint entry from the schema
    assert labels(server, uri, 26, 6)[:2] == ["elbow", "shoulder"]
    assert {"min", "max", "eff", "vel", "damping"} <= set(labels(server, uri, 17, 6))


def test_completion_of_enumerations_and_files(server: Client, folder: Path) -> None:
    text = DEFINITION.replace("    - type: urdf", "    - type: \n    - type: urdf")
    uri, _ = opened(server, folder / "enums.yml", text)
    assert labels(server, uri, 28, 12)[:5] == ["urdf", "sdf", "mjcf", "usd", "smurf"]
    server.change(uri, 2, text.replace("basefile: arm.urdf", "basefile: "))
    assert labels(server, uri, 5, 16) == ["arm.urdf", "arm.urdf.xacro", "arm_segment.xacro", "meshes/"]


def hover(server: Client, uri: str, line: int, character: int) -> str:
    return server.request("textDocument/hover", server.at(uri, line, character))["contents"]["value"]


def test_hover(server: Client, folder: Path) -> None:
    uri, _ = opened(server, folder / "hover.yml", DEFINITION)
    assert hover(server, uri, 9, 6) == (
        "**link upper**\n\nmass: 1 kg\n\nparent joint: shoulder (revolute)\n\n"
        "pose in the root frame: xyz [0, 0, 0.1], rpy [0, 0, 0]\n\narm.urdf:20")
    assert hover(server, uri, 16, 6) == (
        "**joint shoulder** (revolute): base → upper\n\n"
        "axis: [0, 1, 0]\n\nlower: -1.5, upper: 1.5, effort: 10, velocity: 2\n\narm.urdf:13")
    assert hover(server, uri, 17, 19) == "= 0.785398"  # on the 45 of ["deg", 45]
    assert "position limits" in hover(server, uri, 17, 7)  # the key `min`


def test_definition_opens_the_urdf_line_and_files(server: Client, folder: Path) -> None:
    uri, _ = opened(server, folder / "definition.yml", DEFINITION)
    urdf = (folder / "arm.urdf").as_uri()
    assert server.request("textDocument/definition", server.at(uri, 16, 6)) == {
        "uri": urdf, "range": {"start": {"line": 12, "character": 2}, "end": {"line": 12, "character": 8}}}
    joint_line = (folder / "arm.urdf").read_text().split("\n")[12]
    assert joint_line.strip().startswith('<joint name="shoulder"')
    assert server.request("textDocument/definition", server.at(uri, 5, 18))["uri"] == urdf


def test_definition_into_a_xacro_file(server: Client, folder: Path) -> None:
    text = ("model:\n  robotname: arm\n  modelname: arm-model\n  input_models:\n    arm:\n"
            "      basefile: arm.urdf.xacro\n  assemble:\n    model: arm\n  frames:\n    tool:\n"
            "      parent: base\n      xyz: [0, 0, 0.1]\n  joints:\n    shoulder:\n      damping: 0.5\n")
    uri, diagnostics = opened(server, folder / "xacro.yml", text)
    assert diagnostics == []
    xacro = (folder / "arm.urdf.xacro").as_uri()
    assert server.request("textDocument/definition", server.at(uri, 10, 15)) == {  # parent: base
        "uri": xacro, "range": {"start": {"line": 4, "character": 2}, "end": {"line": 4, "character": 7}}}
    # a joint a macro names: the macro's element, in the included file
    macro = server.request("textDocument/definition", server.at(uri, 13, 5))
    assert (macro["uri"], macro["range"]["start"]) == ((folder / "arm_segment.xacro").as_uri(),
                                                       {"line": 3, "character": 4})


def test_rename_across_the_definition(server: Client, folder: Path) -> None:
    uri, _ = opened(server, folder / "rename.yml", DEFINITION)
    edit = server.request("textDocument/rename", {**server.at(uri, 25, 8), "newName": "shoulder_pitch"})
    assert sorted(e["range"]["start"]["line"] for e in edit["changes"][uri]) == [16, 25]
    assert {e["newText"] for e in edit["changes"][uri]} == {"shoulder_pitch"}


def test_document_symbols(server: Client, folder: Path) -> None:
    uri, _ = opened(server, folder / "symbols.yml", DEFINITION)
    (model,) = server.request("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    sections = [s["name"] for s in model["children"]]
    assert sections == ["robotname", "modelname", "input_models", "assemble", "frames", "joints",
                        "collisions", "poses", "export_config"]
    frames = model["children"][4]
    assert [s["name"] for s in frames["children"]] == ["upper", "tool"]


def test_a_defaults_file_updates_the_files_using_it(server: Client, folder: Path) -> None:
    defaults = folder / "arm_defaults.yml"
    base_text = "default_model:\n  joints:\n    shoulder:\n      damping: 0.1\n"
    defaults_uri, _ = opened(server, defaults, base_text)
    text = "defaults: arm_defaults.yml\n" + DEFINITION.replace("elbo:", "elbow:")
    uri, diagnostics = opened(server, folder / "user.yml", text)
    assert diagnostics == []
    server.change(defaults_uri, 2, base_text.replace("shoulder", "shouldr"))  # unsaved: the buffer counts
    (diagnostic,) = server.diagnostics(uri)
    assert diagnostic["code"] == "E0310" and "'shouldr'" in diagnostic["message"]
    assert diagnostic["relatedInformation"][0]["location"]["uri"] == defaults_uri
    assert diagnostic["relatedInformation"][0]["location"]["range"]["start"]["line"] == 2


def test_a_pipeline_file(server: Client, folder: Path) -> None:
    (folder / "arm_model.yml").write_text(DEFINITION.replace("elbo:", "elbow:"), encoding="utf-8")
    text = "pipeline:\n  model_definitions:\n    - arm_model.yml\n    - missing.yml\n"
    _, diagnostics = opened(server, folder / "pipeline.yml", text)
    assert [(d["code"], d["range"]["start"]["line"]) for d in diagnostics] == [("E0601", 3)]


def test_the_server_starts_without_numpy() -> None:
    """numpy (13 MiB) is loaded by the first hover on a link, not by the server's start or a
    check: the server holding TALOS took 81 MiB with it, 68 MiB without."""
    import subprocess
    import sys

    code = ("import sys, mpc.lsp.server, mpc.lsp.analysis, mpc.lsp.completion, mpc.lsp.navigation; "
            "print('numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
