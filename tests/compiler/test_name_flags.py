"""name_editing's `joint_equals_link_name` and `append_link_suffix` (ALWAYS, NAME_DUPLICATES),
from the command line on example-robot-data's UR5 and TALOS arm: the names, every reference
following them (attach parents included), `mpc check` knowing them, the kinematics unchanged."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lxml import etree

from tests.conftest import ERD, write
from tests.mpc_command import mpc

UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"
ARM = ERD / "talos_data/robots/talos_left_arm.urdf"


def _spec(tmp_path: Path, editing: str, children: str = "") -> Path:
    return write(tmp_path / "m.yml", f"""
        model:
          robotname: ur5
          modelname: ur5_model
          input_models:
            ur5: {{basefile: "{UR5}"}}
            arm: {{basefile: "{ARM}"}}
          assemble:
            model: ur5
            name_editing: {editing}
        {children}
        """)


def _tree(urdf: Path) -> dict[str, tuple[str, str]]:
    root = etree.parse(str(urdf)).getroot()
    return {j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))
            for j in root.findall("joint")}


def _world_poses(urdf: Path) -> dict[str, np.ndarray]:
    """Each link's world pose at q = 0, by Pinocchio."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    return {f.name: data.oMf[i].homogeneous for i, f in enumerate(model.frames) if f.type == pin.BODY}


def test_joint_equals_link_name_and_name_duplicates(tmp_path: Path) -> None:
    """Each joint is named after its child link minus `_link`; then the links named as the joint
    above them (`base_frame`, `tool0`) get `_Link`. Pinocchio reads the same robot."""
    spec = _spec(tmp_path, """{joint_equals_link_name: true, append_link_suffix: NAME_DUPLICATES,
                               link_replacements: {"^base$": "base_frame"}}""")
    assert mpc("check", spec).returncode == 0
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    tree = _tree(tmp_path / "out/urdf/ur5.urdf")
    assert tree == {
        "base": ("world", "base_link"), "base_frame": ("base_link", "base_frame_Link"),
        "shoulder": ("base_link", "shoulder_link"), "upper_arm": ("shoulder_link", "upper_arm_link"),
        "forearm": ("upper_arm_link", "forearm_link"), "wrist_1": ("forearm_link", "wrist_1_link"),
        "wrist_2": ("wrist_1_link", "wrist_2_link"), "wrist_3": ("wrist_2_link", "wrist_3_link"),
        "ee": ("wrist_3_link", "ee_link"), "tool0": ("wrist_3_link", "tool0_Link")}
    renamed = {"base": "base_frame_Link", "tool0": "tool0_Link"}
    source = _world_poses(UR5)
    built = _world_poses(tmp_path / "out/urdf/ur5.urdf")
    assert set(built) == {renamed.get(n, n) for n in source}
    assert all(np.allclose(built[renamed.get(n, n)], X, atol=1e-12) for n, X in source.items())
    root = etree.parse(str(tmp_path / "out/urdf/ur5.urdf")).getroot()  # transmissions follow
    assert [t.find("joint").get("name") for t in root.iter("transmission")] == [
        "shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"]


def test_always_and_attach_parents_follow_the_suffix(tmp_path: Path) -> None:
    """ALWAYS suffixes every link not ending in `link`; the children's `joint: parent` is written
    as before editing and finds the suffixed link, for ALWAYS (known from the name) and
    NAME_DUPLICATES (known from the tree)."""
    children = """
            children:
              - model: arm
                name_editing: {prefix: "l_", joint_equals_link_name: true,
                               append_link_suffix: NAME_DUPLICATES, link_replacements: {"_1_link$": "_1"}}
                joint: {parent: tool0, name: mount}
              - model: arm
                name_editing: {prefix: "r_"}
                joint: {parent: base, name: mount2}"""
    spec = _spec(tmp_path, "{append_link_suffix: ALWAYS}", children)
    assert mpc("check", spec).returncode == 0
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    tree = _tree(tmp_path / "out/urdf/ur5.urdf")
    assert tree["world_joint"] == ("world_Link", "base_link")
    assert tree["mount"] == ("tool0_Link", "l_arm_left_1")  # the arm's root: no joint above it
    assert tree["mount2"] == ("base_Link", "r_arm_left_1_link")
    assert tree["l_arm_left_2"] == ("l_arm_left_1", "l_arm_left_2_link")


def test_name_duplicates_parent_in_an_attach(tmp_path: Path) -> None:
    """A child's parent `tool0` is `tool0_Link` after the parent's NAME_DUPLICATES; a typo is
    reported by `mpc check` with the names there are."""
    children = """
            children:
              - model: arm
                joint: {parent: tool0, name: mount}"""
    editing = ('{joint_equals_link_name: true, append_link_suffix: NAME_DUPLICATES, '
               'link_replacements: {"^base$": "b"}}')
    spec = _spec(tmp_path, editing, children)
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    assert _tree(tmp_path / "out/urdf/ur5.urdf")["mount"] == ("tool0_Link", "arm_left_1_link")
    spec.write_text(spec.read_text().replace("parent: tool0", "parent: tool"))
    run = mpc("check", spec)
    assert run.returncode == 1
    assert "error[E0310]: the attaching joint's parent refers to unknown link 'tool'" in run.stderr


def test_joint_names_that_would_clash(tmp_path: Path) -> None:
    """UR5's `world_joint` (child base_link) and `base_link-base_fixed_joint` (child base) would
    both be `base`."""
    spec = _spec(tmp_path, "{joint_equals_link_name: true, joint_prefix: j_}")
    run = mpc("check", spec)
    assert run.returncode == 1
    assert ("error[E0302]: name editing gives two joints the name 'base' ('base_link-base_fixed_joint' "
            "and 'world_joint'): joint_equals_link_name names them after their child links 'base' "
            "and 'base_link'") in run.stderr
    assert ("warning[W0550]: 'joint_prefix' has no effect: joint_equals_link_name names every joint "
            "after its child link") in run.stderr


def test_the_flags_only_in_an_assembly_entry(tmp_path: Path) -> None:
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: ur5
          modelname: ur5_model
          input_models: {{ur5: {{basefile: "{UR5}"}}}}
          assemble: {{model: ur5}}
          frames:
            $name_editing: {{append_link_suffix: ALWAYS}}
        """)
    run = mpc("check", spec)
    assert run.returncode == 1
    assert ("error[E0313]: 'append_link_suffix' has no meaning in frames.$name_editing; it is a key "
            "of an assemble entry's name_editing") in run.stderr


def test_a_child_link_renamed_by_name_duplicates_and_re_rooted(tmp_path: Path) -> None:
    """`child: tool0` of a UR5 whose NAME_DUPLICATES made it `u_tool0_Link`: found, and the UR5
    re-rooted there (the joints above it reversed); Pinocchio weighs both models."""
    import pinocchio as pin

    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: two
          modelname: two_model
          input_models:
            arm: {{basefile: "{ARM}"}}
            ur5: {{basefile: "{UR5}"}}
          assemble:
            model: arm
            children:
              - model: ur5
                name_editing: {{prefix: "u_", joint_equals_link_name: true,
                                append_link_suffix: NAME_DUPLICATES,
                                link_replacements: {{"^u_base$": "u_b"}}}}
                joint: {{parent: arm_left_7_link, child: tool0, name: mount}}
        """)
    assert mpc("check", spec).returncode == 0
    run = mpc("compile", spec, "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    tree = _tree(tmp_path / "out/urdf/two.urdf")
    assert tree["mount"] == ("arm_left_7_link", "u_tool0_Link")
    assert tree["u_tool0"] == ("u_tool0_Link", "u_wrist_3_link")
    assert tree["u_wrist_3"] == ("u_wrist_3_link", "u_wrist_2_link")
    free = pin.JointModelFreeFlyer()
    masses = [pin.computeTotalMass(pin.buildModelFromUrdf(str(p), free))
              for p in (tmp_path / "out/urdf/two.urdf", ARM, UR5)]
    assert abs(masses[0] - masses[1] - masses[2]) <= 1e-12
