"""Round trips through MJCF: URDF → MJCF → mpc → URDF is physically the same robot in
Pinocchio (mass, centre of mass, every link's pose at 11 configurations, joint limits), and
MJCF → mpc → MJCF three times over is MuJoCo's compiled original."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Severity
from tests.backends.mjcf_compare import assert_mjcf_matches
from tests.backends.pin_compare import random_configurations
from tests.backends.test_mjcf_reader import ARM
from tests.conftest import ERD, Diags, write


def _compile(tmp_path: Path, name: str, basefile: Path, export: str, diags: Diags) -> Path:
    (tmp_path / f"{name}.yml").write_text(f"""model:
  robotname: {name}
  modelname: {name}
  input_models:
    base:
      basefile: "{basefile}"
  assemble:
    model: base
  export_config:
    - type: {export}
""")
    options = Options(out=tmp_path / f"out_{name}")
    options.resolver.add_root(basefile.parent)
    compile_model(tmp_path / f"{name}.yml", diags, options)
    assert not diags.has_errors(), diags.summary()
    return tmp_path / f"out_{name}"


def _body_frames(model: pin.Model) -> list[str]:
    return sorted(f.name for f in model.frames if f.type == pin.FrameType.BODY)


@pytest.mark.parametrize("source", ["ur_description/urdf/ur5_robot.urdf",
                                    "double_pendulum_description/urdf/double_pendulum_continuous.urdf"])
def test_urdf_to_mjcf_to_urdf_is_the_same_robot(source: str, tmp_path: Path, diags: Diags) -> None:
    original = ERD / source
    mjcf = _compile(tmp_path, "there", original, "mjcf", diags)
    diags.take("W0500", Severity.WARNING)  # MJCF has no velocity limits
    xml = next((mjcf / "mjcf").glob("*.xml"))
    back = _compile(tmp_path, "back", xml, "urdf", diags)
    while any(d.code == "W0440" for d in diags.diagnostics):  # e.g. the contact exclusions of the MJCF
        diags.take("W0440", Severity.WARNING)
    a = pin.buildModelFromUrdf(str(original), pin.JointModelFreeFlyer())
    b = pin.buildModelFromUrdf(str(back / "urdf" / "back.urdf"), pin.JointModelFreeFlyer())
    assert sorted(a.names) == sorted(b.names)  # the moving joints
    # A root link `world` is MuJoCo's world body, which reads back as no link: the robot's
    # root is the one body below it, and the poses are compared relative to that body.
    common = [n for n in _body_frames(a) if n != "world"]
    assert set(common) <= set(_body_frames(b))
    reference = next(f.name for f in b.frames if f.type == pin.FrameType.BODY)
    assert abs(pin.computeTotalMass(a) - pin.computeTotalMass(b)) <= 1e-9
    da, db = a.createData(), b.createData()
    for q_a in [pin.neutral(a), *random_configurations(a, 10, seed=3)]:
        q_b = pin.neutral(b)
        for jid in range(1, a.njoints):
            k = b.getJointId(a.names[jid])
            q_b[b.idx_qs[k]:b.idx_qs[k] + b.nqs[k]] = q_a[a.idx_qs[jid]:a.idx_qs[jid] + a.nqs[jid]]
            if a.nqs[jid] == 1:
                i, j = a.idx_qs[jid], b.idx_qs[k]
                assert (a.lowerPositionLimit[i], a.upperPositionLimit[i]) == pytest.approx(
                    (b.lowerPositionLimit[j], b.upperPositionLimit[j]), abs=1e-9)
        pin.framesForwardKinematics(a, da, q_a)
        pin.framesForwardKinematics(b, db, q_b)
        body = pin.FrameType.BODY
        ra = np.linalg.inv(da.oMf[a.getFrameId(reference, body)].homogeneous)
        rb = np.linalg.inv(db.oMf[b.getFrameId(reference, body)].homogeneous)
        com_a, com_b = (np.append(pin.centerOfMass(m, d, q), 1.0) for m, d, q in ((a, da, q_a), (b, db, q_b)))
        np.testing.assert_allclose(ra @ com_a, rb @ com_b, atol=1e-9)
        for name in common:
            fa, fb = a.getFrameId(name, body), b.getFrameId(name, body)
            np.testing.assert_allclose(ra @ da.oMf[fa].homogeneous, rb @ db.oMf[fb].homogeneous, atol=1e-9,
                                       err_msg=name)


def test_mjcf_through_mpc_three_times_is_the_same_robot(tmp_path: Path, diags: Diags) -> None:
    source = write(tmp_path / "arm.xml", ARM)
    xml = source
    for name in ("first", "second", "third"):
        read = xml
        xml = _compile(tmp_path, name, xml, "mjcf", diags) / "mjcf" / f"{name}.xml"
        if read != source:  # the <contact><exclude> pairs of jointed links mpc wrote (no bitmasks)
            assert diags.take("W0440", Severity.WARNING).message == \
                f"'{read}' holds what mpc's robot model cannot: contact exclusion ×3; left out"
        diags.take("W0500", Severity.WARNING)  # velocity limits, motor settings
    assert_mjcf_matches(mujoco.MjModel.from_xml_path(str(source)), xml)
