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


Shape = tuple[str, str, tuple[object, ...], np.ndarray]


def _shapes(path: Path, kind: pin.GeometryType, package_dirs: list[str]) -> list[Shape]:
    """Each visual or collision shape of `path` as Pinocchio reads it (its meshes loaded by
    hpp-fcl): the link it is on, its kind, its size (its bounding box, scale applied, and a
    mesh's vertex count) and its placement in the world at q = 0, in a stable order."""
    model = load(path)
    geometry = pin.buildGeomFromUrdf(model, str(path), kind, package_dirs=[*package_dirs, str(path.parent)])
    data, geometry_data = model.createData(), pin.GeometryData(geometry)
    pin.updateGeometryPlacements(model, data, geometry, geometry_data, pin.neutral(model))
    shapes = []
    for i, g in enumerate(geometry.geometryObjects):
        shape = g.geometry
        shape.computeLocalAABB()
        box = shape.aabb_local
        size = (getattr(shape, "num_vertices", None), *np.round(box.min_, 9), *np.round(box.max_, 9))
        shapes.append((model.frames[g.parentFrame].name, type(shape).__name__, size,
                       geometry_data.oMg[i].homogeneous))
    return sorted(shapes, key=lambda s: (s[0], s[1], str(s[2]), tuple(s[3].round(6).ravel() + 0.0)))


def assert_same_shapes(a_path: Path, b_path: Path, package_dirs: list[str], tol: float = 1e-9) -> None:
    """The same visuals and collisions, link by link: kind, size (a mesh's vertex count and
    bounds) and placement, as Pinocchio loads them."""
    for kind in (pin.GeometryType.VISUAL, pin.GeometryType.COLLISION):
        a, b = _shapes(a_path, kind, package_dirs), _shapes(b_path, kind, package_dirs)
        assert [s[:3] for s in a] == [s[:3] for s in b], kind
        for sa, sb in zip(a, b, strict=True):
            np.testing.assert_allclose(sa[3], sb[3], atol=tol, rtol=0, err_msg=f"{kind} {sa[0]}")
