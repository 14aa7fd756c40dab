"""Completion and go to definition where names depend on where the cursor is (issue 29.17),
through the real `mpc lsp` with the messages an editor sends:

- a child's `joint: parent:` offers the parent's links as they are there (after its name
  editing and cuts, with the children attached before), in block and in flow style;
- a pose written as a flow mapping (`reach: {…}`) offers the robot's joints;
- go to definition of a link or joint of a xacro model opens the file that writes it: an
  included file (relative, `$(find pkg)`), the element of the macro that made it (not another
  macro that could have), for a renamed element too.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.lsp.client import Client

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"

TWO = """\
model:
  robotname: two
  modelname: two
  input_models:
    arm: {basefile: arm.urdf}
    grip: {basefile: gripper.urdf}
  assemble:
    model: arm
    name_editing: {prefix: "p_"}
    remove_beyond: p_upper
    children:
      - model: grip
        name_editing: {prefix: "g_"}
        joint:
          parent: p_base
      - model: grip
        name_editing: {prefix: "h_"}
        joint: {parent: p_base, name: second}
  poses:
    reach: {p_shoulder: 0.5, }
    rest:
      p_shoulder: 0
"""

# A xacro robot whose links come from an include found relatively, an include found by
# $(find), and a macro of the second include.
TOP = """\
<?xml version="1.0"?>
<robot name="bot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="parts/body.xacro"/>
  <xacro:include filename="$(find bot_parts)/urdf/leg.xacro"/>
  <xacro:body/>
  <xacro:leg side="left" parent="torso"/>
  <xacro:leg side="right" parent="torso"/>
</robot>
"""
BODY = """\
<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="body">
    <link name="torso">
      <inertial><mass value="3"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    </link>
  </xacro:macro>
</robot>
"""
LEG = """\
<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="leg" params="side parent">
    <joint name="${side}_hip" type="revolute">
      <parent link="${parent}"/>
      <child link="${side}_thigh"/>
      <axis xyz="0 1 0"/>
      <limit lower="-1" upper="1" effort="10" velocity="2"/>
    </joint>
    <link name="${side}_thigh">
      <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
      </inertial>
    </link>
  </xacro:macro>
  <xacro:macro name="spare" params="part">
    <link name="${part}_thigh"/>
  </xacro:macro>
</robot>
"""
BOT = """\
model:
  robotname: bot
  modelname: bot
  input_models:
    bot: {basefile: bot.urdf.xacro}
  assemble:
    model: bot
  frames:
    left_thigh:
      name_editing: {suffix: _x}
    torso:
      name_editing: {suffix: _y}
  joints:
    right_hip:
      damping: 0.1
  collisions:
    left_thigh_x:
      shape: box
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    work = tmp_path_factory.mktemp("names")
    for name in ("arm.urdf", "gripper.urdf"):
        shutil.copy(EXAMPLES / name, work / name)
    shutil.copytree(EXAMPLES / "meshes", work / "meshes")
    (work / "parts").mkdir()
    (work / "parts" / "body.xacro").write_text(BODY, encoding="utf-8")
    package = work / "elsewhere" / "bot_parts"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>bot_parts</name></package>\n", encoding="utf-8")
    (package / "urdf" / "leg.xacro").write_text(LEG, encoding="utf-8")
    (work / "bot.urdf.xacro").write_text(TOP, encoding="utf-8")
    return work


@pytest.fixture(scope="module")
def server(folder: Path) -> Client:
    client = Client("--package", f"bot_parts={folder / 'elsewhere' / 'bot_parts'}",
                    env={**os.environ, "MPC_CACHE_DIR": str(folder / "cache")}, cwd=folder)
    client.initialize(folder)
    yield client
    assert client.close() == 0


def opened(server: Client, path: Path, text: str) -> str:
    path.write_text(text, encoding="utf-8")
    uri = server.open(path)
    assert server.diagnostics(uri, 1) == []
    return uri


def labels(server: Client, uri: str, line: int, character: int) -> list[str]:
    answer = server.request("textDocument/completion", {
        **server.at(uri, line, character), "context": {"triggerKind": 1}})
    return [item["label"] for item in answer["items"]]


def test_parent_of_a_child_joint_in_block_style(server: Client, folder: Path) -> None:
    uri = opened(server, folder / "block.yml", TWO)
    # the parent after its prefix and its remove_beyond; not the gripper's links
    assert labels(server, uri, 14, 18) == ["p_base", "p_upper"]


def test_parent_of_a_child_joint_in_flow_style(server: Client, folder: Path) -> None:
    uri = opened(server, folder / "flow.yml", TWO)
    # the second child: the parent as it is then, with the first child attached
    assert labels(server, uri, 17, 24) == ["g_finger_left", "g_finger_right", "g_palm", "g_tcp",
                                           "p_base", "p_upper"]


def test_child_of_a_child_joint(server: Client, folder: Path) -> None:
    text = TWO.replace("          parent: p_base\n", "          parent: p_base\n          child: g_palm\n")
    text = text.replace("{parent: p_base, name: second}", "{parent: p_base, child: h_tcp, name: second}")
    uri = opened(server, folder / "child.yml", text)
    # the child's links (after its name editing), not the parent's
    assert labels(server, uri, 15, 17) == ["g_finger_left", "g_finger_right", "g_palm", "g_tcp"]
    assert labels(server, uri, 18, 40) == ["h_finger_left", "h_finger_right", "h_palm", "h_tcp"]


def test_a_child_entry_written_as_one_flow_mapping(server: Client, folder: Path) -> None:
    entry = '      - {model: grip, name_editing: {prefix: "g_"}, joint: {parent: p_base, child: g_palm}}\n'
    text = TWO.split("    children:\n")[0] + "    children:\n" + entry
    uri = opened(server, folder / "item.yml", text)
    assert labels(server, uri, 11, entry.index("p_base")) == ["p_base", "p_upper"]
    assert labels(server, uri, 11, entry.index("g_palm")) == ["g_finger_left", "g_finger_right", "g_palm",
                                                              "g_tcp"]


JOINTS = ["g_finger_left_joint", "g_finger_right_joint", "g_tcp_joint", "h_finger_left_joint",
          "h_finger_right_joint", "h_tcp_joint", "p_base2g_palm", "p_shoulder", "second"]


def test_joints_of_a_pose_in_flow_style(server: Client, folder: Path) -> None:
    uri = opened(server, folder / "pose.yml", TWO)
    assert labels(server, uri, 19, 29)[:len(JOINTS)] == JOINTS  # reach: {p_shoulder: 0.5, |}
    assert labels(server, uri, 19, 12)[:len(JOINTS)] == JOINTS  # reach: {|
    assert labels(server, uri, 21, 6)[:len(JOINTS)] == JOINTS  # the same pose in block style


def definition(server: Client, uri: str, line: int, character: int) -> tuple[str, int, int]:
    found = server.request("textDocument/definition", server.at(uri, line, character))
    return found["uri"], found["range"]["start"]["line"], found["range"]["start"]["character"]


def test_definition_in_the_files_a_xacro_includes(server: Client, folder: Path) -> None:
    uri = opened(server, folder / "bot.yml", BOT)
    body = (folder / "parts" / "body.xacro").as_uri()
    leg = (folder / "elsewhere" / "bot_parts" / "urdf" / "leg.xacro").as_uri()
    assert definition(server, uri, 10, 5) == (body, 3, 4)  # torso: written as it is
    # left_thigh: "${side}_thigh" of the macro that made it (an unused macro could make it too)
    assert definition(server, uri, 8, 5) == (leg, 9, 4)
    assert definition(server, uri, 16, 5) == (leg, 9, 4)  # the same link after its renaming
    assert definition(server, uri, 13, 5) == (leg, 3, 4)  # right_hip: "${side}_hip"
    hover = server.request("textDocument/hover", server.at(uri, 8, 5))["contents"]["value"]
    assert hover.startswith("**link left_thigh**\n\nmass: 1 kg") and hover.endswith("\n\nleg.xacro:10")
    for line, text in ((3, '<link name="torso">'), (9, '<link name="${side}_thigh">')):
        assert (BODY if line == 3 else LEG).split("\n")[line].strip() == text
