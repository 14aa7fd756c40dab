"""Mirroring, checked with Pinocchio against ground truth and against the reflection itself."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh

from mpc.backends import urdf
from mpc.core.diagnostics import Sink
from mpc.ir.kinematics import link_in_root, pose_matrix
from mpc.ir.mirror import axis_flip, reflection
from tests.backends.pin_compare import random_configurations
from tests.conftest import ERD, Diags, compile_file, write

ALLEGRO = ERD / "allegro_hand_description/urdf"


def _mirror(tmp_path: Path, source: Path, mirror: str = "{}", name: str = "mirrored") -> Path:
    spec = write(tmp_path / "mirror.yml", f"""
        model:
          robotname: {name}
          modelname: {name}
          input_models:
            src: {{basefile: "{source}"}}
          assemble:
            model: src
            mirror: {mirror}
          export_config: [{{type: urdf, mesh_format: input_type}}]
        """)
    result = compile_file(spec, tmp_path / "out", Diags())
    assert result.out is not None
    return result.out / "urdf" / f"{name}.urdf"


def _frames(model: pin.Model, q: np.ndarray) -> dict[str, np.ndarray]:
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return {f.name: data.oMf[i].homogeneous.copy() for i, f in enumerate(model.frames)
            if f.type == pin.BODY}


def test_mirrored_right_hand_is_the_left_hand(tmp_path: Path) -> None:
    """allegro_left_hand.urdf was made by hand as the mirror image of the right hand."""
    out = _mirror(tmp_path, ALLEGRO / "allegro_right_hand.urdf")
    ours = pin.buildModelFromUrdf(str(out))
    truth = pin.buildModelFromUrdf(str(ALLEGRO / "allegro_left_hand.urdf"))
    a, b = _frames(ours, pin.neutral(ours)), _frames(truth, pin.neutral(truth))
    assert a.keys() == b.keys()
    for name in b:
        np.testing.assert_allclose(a[name], b[name], atol=1e-9, rtol=0, err_msg=name)
    # Masses equal, COMs (in the root frame) reflected onto the left hand's.
    mine, left = urdf.read(out, Sink()), urdf.read(ALLEGRO / "allegro_left_hand.urdf", Sink())
    assert mine is not None and left is not None
    for name, link in left.links.items():
        assert (link.inertial is None) == (mine.links[name].inertial is None)
        if link.inertial is None:
            continue
        assert mine.links[name].inertial.mass == link.inertial.mass

        def com(robot, lk):
            return (link_in_root(robot, lk.name) @ pose_matrix(lk.inertial.origin))[:3, 3]

        np.testing.assert_allclose(com(mine, mine.links[name]), com(left, link), atol=1e-9, err_msg=name)


def test_mirrored_meshes_have_positive_volume_and_reflected_bounds(tmp_path: Path) -> None:
    out = _mirror(tmp_path, ALLEGRO / "allegro_right_hand.urdf")
    mirrored = sorted((out.parent.parent / "meshes").rglob("*_mirrored.stl"))
    assert len(mirrored) == 11
    for path in mirrored:
        source = ALLEGRO.parent / "meshes" / path.name.replace("_mirrored.stl", ".STL")
        a = trimesh.load(path, force="mesh", process=False)
        b = trimesh.load(source, force="mesh", process=False)
        flip = np.array([1.0, -1.0, 1.0])
        np.testing.assert_allclose(np.sort(a.bounds * flip, axis=0), b.bounds, atol=1e-6)
        if b.is_watertight:
            assert a.volume > 0 and a.volume == pytest.approx(b.volume, rel=1e-9)


@pytest.mark.parametrize(("model", "mirror", "plane", "flip"), [
    ("panda_description/urdf/panda.urdf", "{}", (0, 1, 0), 1),
    ("talos_data/robots/talos_left_arm.urdf", "{plane: [1, 1, 0], flip_axis: 2}", (1, 1, 0), 2),
    ("tiago_description/robots/tiago.urdf", "{plane: [0, 0, 1], flip_axis: 0}", (0, 0, 1), 0),
])
def test_mirror_in_motion(tmp_path: Path, model: str, mirror: str, plane: tuple, flip: int) -> None:
    """At any configuration, the mirror at q' (−q revolute, +q prismatic) is the reflection."""
    out = _mirror(tmp_path, ERD / model, mirror)
    orig, mirr = pin.buildModelFromUrdf(str(ERD / model)), pin.buildModelFromUrdf(str(out))
    assert list(orig.names) == list(mirr.names)
    M, F = reflection(plane), axis_flip(flip)
    root = orig.frames[1].name  # the root link's frame: it stays as it is
    for q in random_configurations(orig, 5, seed=3):
        q_m = q.copy()
        for jid in range(1, orig.njoints):
            if orig.joints[jid].shortname() in ("JointModelRX", "JointModelRY", "JointModelRZ",
                                                "JointModelRevoluteUnaligned", "JointModelRUBX",
                                                "JointModelRUBY", "JointModelRUBZ",
                                                "JointModelRevoluteUnboundedUnaligned"):
                i, n = orig.idx_qs[jid], orig.nqs[jid]
                if n == 1:
                    q_m[i] = -q[i]
                else:  # unbounded revolute: (cos, sin) → (cos, −sin)
                    q_m[i + 1] = -q[i + 1]
        a, b = _frames(orig, q), _frames(mirr, q_m)
        for name, X in a.items():
            expected = np.eye(4)
            expected[:3, :3] = M @ X[:3, :3] @ (F if name != root else M)
            expected[:3, 3] = M @ X[:3, 3]
            np.testing.assert_allclose(b[name], expected, atol=1e-9, rtol=0, err_msg=name)
