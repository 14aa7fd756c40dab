"""Assembly on real models: a robot rebuilt from its parts is the robot; renames reach every
reference; derived_base chains and git inputs work; mistakes are located diagnostics."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin
from lxml import etree

from mpc.backends import urdf
from mpc.core.diagnostics import Sink
from mpc.ir.kinematics import link_in_root
from tests.backends.pin_compare import load, random_configurations
from tests.conftest import ERD, Diags, compile_file, definition, write
from tests.fixtures import ARM_URDF, arm

A1 = ERD / "a1_description/urdf/a1.urdf"
HIPS = {"FL": "0.1805, 0.047", "FR": "0.1805, -0.047", "RL": "-0.1805, 0.047", "RR": "-0.1805, -0.047"}


def _leg(side: str, mirror: str = "") -> str:
    """An assemble child: one leg of the a1 quadruped, attached with its original hip joint."""
    return (f"\n      - model: a1\n        take_leaf: {'FL' if mirror else side}_hip\n"
            + (f"        mirror: {mirror}\n" if mirror else "")
            + f"        joint: {{parent: trunk, name: {side}_hip_joint, type: revolute, "
            f"xyz: [{HIPS[side]}, 0], axis: [1, 0, 0], min: -0.8028514559173915, "
            "max: 0.8028514559173915, eff: 33.5, vel: 21.0}")


def test_a1_rebuilt_from_its_parts_is_a1(tmp_path: Path) -> None:
    """Torso by remove_beyond, legs by take_leaf, the front right leg mirrored from the left.

    a1 is exactly symmetric (masses, COMs and inertias), so the rebuilt robot must have the
    same dynamics, once the joints whose axes the mirror reflected turn the other way.
    """
    legs = _leg("FL") + _leg("FR", "{name_replacements: {'^FL_': 'FR_'}}") + _leg("RL") + _leg("RR")
    spec = tmp_path / "a1.yml"
    spec.write_text(f"""model:
  robotname: a1
  modelname: a1-rebuilt
  input_models:
    a1: {{basefile: "{A1}"}}
  assemble:
    model: a1
    remove_beyond: trunk
    children:
      - model: a1
        take_leaf: imu_link
        joint: {{parent: trunk, name: imu_joint}}{legs}
""")
    result = compile_file(spec, tmp_path / "out", Diags())
    assert result.out is not None
    whole, built = load(A1), load(result.out / "urdf/a1.urdf")
    assert sorted(whole.names) == sorted(built.names)
    assert abs(pin.computeTotalMass(whole) - pin.computeTotalMass(built)) < 1e-12
    # The mirrored leg's joints turn the other way where their axes were reflected.
    ir_whole, ir_built = urdf.read(A1, Sink()), urdf.read(result.out / "urdf/a1.urdf", Sink())
    assert ir_whole is not None and ir_built is not None
    sign = {}
    for name, joint in ir_whole.joints.items():
        if joint.type == "fixed":
            continue
        other = ir_built.joints[name]
        axis_w = link_in_root(ir_whole, joint.child)[:3, :3] @ np.asarray(joint.axis)
        axis_b = link_in_root(ir_built, other.child)[:3, :3] @ np.asarray(other.axis)
        assert abs(abs(axis_w @ axis_b) - 1) < 1e-12, name
        sign[name] = float(np.sign(axis_w @ axis_b))
    assert sorted(n for n, s in sign.items() if s < 0) == ["FR_calf_joint", "FR_thigh_joint"]
    dw, db = whole.createData(), built.createData()
    for q in random_configurations(whole, 5, seed=11):
        q_b = pin.neutral(built)
        q_b[:7] = q[:7]
        for name, s in sign.items():
            q_b[built.idx_qs[built.getJointId(name)]] = s * q[whole.idx_qs[whole.getJointId(name)]]
        np.testing.assert_allclose(pin.centerOfMass(whole, dw, q), pin.centerOfMass(built, db, q_b),
                                   atol=1e-6)
        g_w = pin.computeGeneralizedGravity(whole, dw, q)
        g_b = pin.computeGeneralizedGravity(built, db, q_b)
        np.testing.assert_allclose(g_w[:6], g_b[:6], atol=1e-6)
        for name, s in sign.items():
            i, j = whole.idx_vs[whole.getJointId(name)], built.idx_vs[built.getJointId(name)]
            assert abs(g_w[i] - s * g_b[j]) < 1e-6, name


def test_rename_reaches_every_reference(tmp_path: Path) -> None:
    talos = ERD / "talos_data/robots/talos_full_v2.urdf"
    spec = write(tmp_path / "t.yml", f"""
        model:
          robotname: talos
          modelname: talos-renamed
          input_models: {{talos: {{basefile: "{talos}"}}}}
          assemble:
            model: talos
            name_editing:
              link_prefix: "t_"
              replacements: [{{"^arm_left_": "left_arm_"}}, {{"_joint$": "_j"}}]
        """)
    result = compile_file(spec, tmp_path / "out", Diags())
    assert result.out is not None
    out = result.out / "urdf/talos.urdf"
    src_model, out_model = load(talos), load(out)
    def edited(n: str) -> str:
        n = n.replace("arm_left_", "left_arm_")
        return n.removesuffix("_joint") + "_j" if n.endswith("_joint") else n

    # not pinocchio's 'universe' and free flyer 'root_joint'
    renamed = {n: edited(n) for n in src_model.names[2:]}
    renamed.update(universe="universe", root_joint="root_joint")
    assert sorted(out_model.names) == sorted(renamed.values())
    root = etree.parse(str(out)).getroot()
    links = {e.get("name") for e in root.findall("link")}
    joints = {e.get("name") for e in root.findall("joint")}
    assert all(n.startswith("t_") for n in links)
    gazebo = [g.get("reference") for g in root.findall("gazebo") if g.get("reference")]
    assert gazebo and all(r in links | joints for r in gazebo)
    for t in root.findall("transmission"):
        for j in t.findall("joint"):
            assert j.get("name") in joints
    for m in root.iter("mimic"):
        assert m.get("joint") in joints
    # Same dynamics once the names are mapped.
    q = random_configurations(src_model, 1, seed=5)[0]
    q_out = pin.neutral(out_model)
    q_out[:7] = q[:7]
    for jid in range(2, src_model.njoints):
        oid = out_model.getJointId(renamed[src_model.names[jid]])
        q_out[out_model.idx_qs[oid]] = q[src_model.idx_qs[jid]]
    np.testing.assert_allclose(pin.computeGeneralizedGravity(src_model, src_model.createData(), q)[:6],
                               pin.computeGeneralizedGravity(out_model, out_model.createData(), q_out)[:6],
                               atol=1e-9)


def test_derived_base_chain_of_three(tmp_path: Path) -> None:
    arm(tmp_path)
    write(tmp_path / "a.yml", definition("arm.urdf", "stl", "a"))
    write(tmp_path / "b.yml", """
        model:
          robotname: b
          modelname: b
          input_models: {a: {derived_base: a.yml}}
          assemble: {model: a, take_leaf: upper}
        """)
    write(tmp_path / "c.yml", """
        model:
          robotname: c
          modelname: c
          input_models: {b: {derived_base: b.yml}}
          assemble: {model: b, name_editing: {prefix: "c_"}}
        """)
    result = compile_file(tmp_path / "c.yml", tmp_path / "out", Diags())
    assert result.out is not None
    root = etree.parse(str(result.out / "urdf/c.urdf")).getroot()
    assert [e.get("name") for e in root.findall("link")] == ["c_upper", "c_lower"]
    assert [e.get("name") for e in root.findall("joint")] == ["c_elbow"]


def _git(cwd: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, text=True,
                          env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
                               "GIT_COMMITTER_EMAIL": "t@t", "PATH": "/usr/bin:/bin"}).stdout.strip()


def test_repo_input_at_a_pinned_commit(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    repo = tmp_path / "models"
    arm(repo)
    _git(repo, "init", "-q", "-b", "main")
    _git(repo, "add", "-A")
    _git(repo, "commit", "-q", "-m", "arm v1")
    first = _git(repo, "rev-parse", "HEAD")
    (repo / "arm.urdf").write_text(ARM_URDF.replace('<mass value="2"/>', '<mass value="3"/>'))
    _git(repo, "commit", "-qam", "arm v2")
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm-from-git
          input_models:
            arm: {{repo: {{git: "file://{repo}", commit: "{first[:10]}", model_in_repo: arm.urdf}}}}
          assemble: {{model: arm}}
        """)
    result = compile_file(spec, tmp_path / "out", Diags())
    assert result.out is not None
    masses = [m.get("value") for m in etree.parse(str(result.out / "urdf/arm.urdf")).iter("mass")]
    assert masses == ["2", "1", "0.5"]
    assert (tmp_path / "cache/repos").is_dir()
    # A second build reads the cache; an unknown commit is a located diagnostic.
    assert compile_file(spec, tmp_path / "out2", Diags()).out is not None
    spec.write_text(spec.read_text().replace(first[:10], "0123456789"))
    sink = Diags()
    assert compile_file(spec, tmp_path / "out3", sink).out is None
    d = sink.take_error("E0604")
    assert d.message.startswith(f"cannot get '0123456789' of repository 'file://{repo}'")
    assert (d.span.line, d.span.col) == (5, 17)
