"""submodel exports: the part of TALOS between start and stop, checked with Pinocchio."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from tests.conftest import ERD, Diags, compile_file, write

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"
HEAD = f"""
model:
  robotname: talos
  modelname: talos_model
  input_models: {{talos: {{basefile: "{TALOS}"}}}}
  assemble: {{model: talos}}
"""
ARM = ["torso_2_link"] + [f"arm_left_{i}_link" for i in range(1, 8)]


def links_of(model: pin.Model) -> set[str]:
    return {f.name for f in model.frames if f.type == pin.FrameType.BODY}


def test_arm_with_a_floating_base_is_the_same_arm(tmp_path: Path) -> None:
    """The submodel from torso_2_link to arm_left_7_link: a free flyer, the arm's 7 joints,
    the mass of those 8 links, and every link where it is in the whole robot."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: urdf}
    - {type: submodel, name: left_arm, start: torso_2_link, stop: arm_left_7_link, add_floating_base: true}
""")
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    whole = pin.buildModelFromUrdf(str(out / "urdf/talos.urdf"))
    arm = pin.buildModelFromUrdf(str(out / "submodels/left_arm/urdf/left_arm.urdf"))
    assert arm.joints[1].shortname() == "JointModelFreeFlyer"
    assert list(arm.names)[2:] == [f"arm_left_{i}_joint" for i in range(1, 8)]
    assert links_of(arm) == set(ARM) | {"world"}
    urdf = out / "urdf/talos.urdf"
    assert np.isclose(pin.computeTotalMass(arm), sum(_mass(urdf, link) for link in ARM), rtol=0, atol=1e-12)

    rng = np.random.default_rng(3)
    q_whole = pin.neutral(whole)
    q_arm = pin.neutral(arm)
    for i in range(1, 8):
        value = rng.uniform(-1, 1)
        q_whole[whole.joints[whole.getJointId(f"arm_left_{i}_joint")].idx_q] = value
        q_arm[arm.joints[arm.getJointId(f"arm_left_{i}_joint")].idx_q] = value
    dw, da = whole.createData(), arm.createData()
    pin.framesForwardKinematics(whole, dw, q_whole)
    pin.framesForwardKinematics(arm, da, q_arm)
    base_w = dw.oMf[whole.getFrameId("torso_2_link")]
    base_a = da.oMf[arm.getFrameId("torso_2_link")]
    for link in ARM:
        in_whole = base_w.actInv(dw.oMf[whole.getFrameId(link)])
        in_arm = base_a.actInv(da.oMf[arm.getFrameId(link)])
        assert np.allclose(in_whole.homogeneous, in_arm.homogeneous, atol=1e-12), link


def _mass(urdf: Path, link: str) -> float:
    from lxml import etree

    found = etree.parse(str(urdf)).getroot().find(f"link[@name='{link}']/inertial/mass")
    return float(found.get("value")) if found is not None else 0.0


def test_stop_patterns_keep_exactly_the_links_between(tmp_path: Path) -> None:
    """`stop: leg_.*_6_link` from the root: base_link and the twelve leg links, nothing of the
    torso, arms or soles; with include_unstopped_branches the torso and arms come back, the
    soles below the stops do not."""
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: urdf}
    - type: submodel
      name: legs
      stop: ["leg_.*_6_link"]
      export_config: [{type: urdf}, {type: joint_limits}]
    - type: submodel
      name: no_feet
      stop: ["leg_.*_6_link"]
      include_unstopped_branches: true
""")
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    legs = pin.buildModelFromUrdf(str(out / "submodels/legs/urdf/legs.urdf"))
    assert links_of(legs) == {"base_link"} | {f"leg_{s}_{i}_link" for s in ("left", "right")
                                                for i in range(1, 7)}
    limits = (out / "submodels/legs/joint_limits.yml").read_text()
    assert "leg_left_6_joint" in limits and "arm_" not in limits
    whole = pin.buildModelFromUrdf(str(out / "urdf/talos.urdf"))
    no_feet = pin.buildModelFromUrdf(str(out / "submodels/no_feet/urdf/no_feet.urdf"))
    below_stops = {f.name for f in whole.frames if f.type == pin.FrameType.BODY} - links_of(no_feet)
    assert below_stops == {"left_sole_link", "right_sole_link"}
    assert whole.nq == no_feet.nq


def test_a_start_that_is_not_a_link(tmp_path: Path) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """
  export_config:
    - {type: submodel, name: arm, start: torso_3_link}
""")
    diags = Diags()
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert [(d.code, d.message, d.span.line) for d in diags.diagnostics] == [
        ("E0310", "submodel 'arm' starts at unknown link 'torso_3_link'; did you mean 'torso_2_link'?", 8)]
