"""Physical equality of two URDF files, measured with Pinocchio (free-flyer root)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin


def load(path: Path) -> pin.Model:
    # A free-flyer root makes the root link's mass count (a fixed base drops it).
    return pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())


def random_configurations(model: pin.Model, n: int, seed: int) -> list[np.ndarray]:
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    lower[:3], upper[:3] = -1.0, 1.0  # the free flyer's translation is unbounded
    bounded = np.isfinite(lower) & np.isfinite(upper) & (lower <= upper)
    lower[~bounded], upper[~bounded] = -np.pi, np.pi
    pin.seed(seed)
    return [pin.randomConfiguration(model, lower, upper) for _ in range(n)]


def _q_for(q: np.ndarray, src: pin.Model, dst: pin.Model) -> np.ndarray:
    """q of `src` re-indexed for `dst` by joint name."""
    out = pin.neutral(dst)
    for jid in range(1, src.njoints):
        name = src.names[jid]
        did = dst.getJointId(name)
        a, b = src.idx_qs[jid], dst.idx_qs[did]
        out[b:b + src.nqs[jid]] = q[a:a + src.nqs[jid]]
    return out


def assert_same_physics(a_path: Path, b_path: Path, tol: float = 1e-9, n_random: int = 3) -> None:
    """Same joint and frame names, total mass, COM, gravity torques and frame placements."""
    a, b = load(a_path), load(b_path)
    assert sorted(a.names) == sorted(b.names)
    assert sorted(f.name for f in a.frames) == sorted(f.name for f in b.frames)
    da, db = a.createData(), b.createData()
    assert abs(pin.computeTotalMass(a) - pin.computeTotalMass(b)) <= tol
    for q_a in [pin.neutral(a), *random_configurations(a, n_random, seed=7)]:
        q_b = _q_for(q_a, a, b)
        np.testing.assert_allclose(pin.centerOfMass(a, da, q_a), pin.centerOfMass(b, db, q_b),
                                   atol=tol, rtol=0)
        g_a = pin.computeGeneralizedGravity(a, da, q_a)
        g_b = pin.computeGeneralizedGravity(b, db, q_b)
        for jid in range(1, a.njoints):
            bid = b.getJointId(a.names[jid])
            va, vb = a.idx_vs[jid], b.idx_vs[bid]
            np.testing.assert_allclose(g_a[va:va + a.nvs[jid]], g_b[vb:vb + b.nvs[bid]],
                                       atol=tol, rtol=0, err_msg=a.names[jid])
        pin.framesForwardKinematics(a, da, q_a)
        pin.framesForwardKinematics(b, db, q_b)
        for fid, frame in enumerate(a.frames):
            bid = b.getFrameId(frame.name, frame.type)
            np.testing.assert_allclose(da.oMf[fid].homogeneous, db.oMf[bid].homogeneous,
                                       atol=tol, rtol=0, err_msg=frame.name)
