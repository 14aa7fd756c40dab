"""The usd export of example-robot-data robots, read back: usd-core gives every link's pose,
every body's mass, centre of mass and inertia and every joint's frame, axis and limits equal
to Pinocchio's model of the URDF (1e-9 where USD stores doubles, float32 precision where
UsdPhysics stores floats); Newton, an independent reader of USD physics, gives the same
masses, inertias, joint limits and velocity limits; usd-core's validators report nothing."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from pxr import Gf, Usd, UsdGeom, UsdPhysics, UsdValidation

from mpc.backends import urdf_reader, usd
from mpc.backends.usd import _no_mass
from mpc.core.diagnostics import Severity, Sink
from mpc.core.span import Span
from mpc.ir.program import UsdExport
from mpc.ir.robot import Robot
from tests.backends.newton_read import newton_reads
from tests.conftest import ERD

pytestmark = pytest.mark.long

ROBOTS = ("ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
          "solo_description/robots/solo12.urdf", "talos_data/robots/talos_reduced.urdf")
FLOAT = 1e-6  # float32's precision, relative (UsdPhysics stores floats)
DOUBLE = 1e-9


class Asset:
    """One robot: its IR, its USD stage, Pinocchio's model at q = 0, and the prims by the
    names of their elements (`mpc:name`)."""

    def __init__(self, rel: str, folder: Path) -> None:
        self.urdf = ERD / rel
        sink = Sink()
        robot = urdf_reader.read(self.urdf, sink)
        assert robot is not None
        self.robot: Robot = robot
        usd.emit(robot, UsdExport(span=Span("robots.yml", 1, 1)), folder, sink)
        assert not sink.has_errors(), [str(d) for d in sink.diagnostics]
        assert {d.code for d in sink.diagnostics if d.severity is not Severity.ERROR} <= {"W0500"}
        self.path = folder / "usd" / f"{robot.name}.usda"
        self.stage = Usd.Stage.Open(str(self.path))
        self.model = pin.buildModelFromUrdf(str(self.urdf), pin.JointModelFreeFlyer())
        self.data = self.model.createData()
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        root = self.stage.GetDefaultPrim()
        self.links = {p.GetAttribute("mpc:name").Get(): p for p in root.GetChildren() if p.IsA(UsdGeom.Xform)}
        joints = root.GetChild("joints").GetChildren()
        self.joints = {p.GetAttribute("mpc:name").Get(): p for p in joints}


@pytest.fixture(scope="module")
def assets(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Asset]:
    return {rel: Asset(rel, tmp_path_factory.mktemp(Path(rel).stem)) for rel in ROBOTS}


@pytest.fixture(params=ROBOTS)
def asset(request: pytest.FixtureRequest, assets: dict[str, Asset]) -> Asset:
    return assets[request.param]


def world(prim: Usd.Prim) -> np.ndarray:
    """A prim's pose in the stage (column vectors), in doubles."""
    return np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())).T


def rotation(q: Gf.Quatf | Gf.Quatd) -> np.ndarray:
    w, (x, y, z) = q.GetReal(), q.GetImaginary()
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def joint_frames(asset: Asset, prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    """The joint's frame in the world as body0 and as body1 place it."""
    j = UsdPhysics.Joint(prim)
    out = []
    for rel, pos, rot in ((j.GetBody0Rel(), j.GetLocalPos0Attr(), j.GetLocalRot0Attr()),
                          (j.GetBody1Rel(), j.GetLocalPos1Attr(), j.GetLocalRot1Attr())):
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = rotation(rot.Get()), np.array(pos.Get(), dtype=float)
        out.append(world(asset.stage.GetPrimAtPath(rel.GetTargets()[0])) @ X)
    return out[0], out[1]


def usd_inertia(prim: Usd.Prim) -> pin.Inertia:
    """The link's mass properties as UsdPhysics holds them, in the link frame."""
    mass = UsdPhysics.MassAPI(prim)
    m = mass.GetMassAttr().Get() if mass.GetMassAttr().HasAuthoredValue() else 0.0
    com = np.array(mass.GetCenterOfMassAttr().Get() or (0, 0, 0), dtype=float)
    I = np.zeros((3, 3))  # noqa: E741
    if mass.GetDiagonalInertiaAttr().HasAuthoredValue():
        R = rotation(mass.GetPrincipalAxesAttr().Get())
        I = R @ np.diag(np.array(mass.GetDiagonalInertiaAttr().Get(), dtype=float)) @ R.T  # noqa: E741
    return pin.Inertia(float(m), com, I)


def test_every_link_sits_where_pinocchio_puts_it(asset: Asset) -> None:
    assert sorted(asset.links) == sorted(asset.robot.links)
    for name, prim in asset.links.items():
        fid = asset.model.getFrameId(name, pin.BODY)
        np.testing.assert_allclose(world(prim), asset.data.oMf[fid].homogeneous, atol=DOUBLE, rtol=0,
                                   err_msg=name)


def test_every_bodys_mass_com_and_inertia_are_pinocchios(asset: Asset) -> None:
    """Pinocchio merges the links welded to a joint's body: the links' USD inertias, summed in
    the world, equal each joint's body inertia placed in the world."""
    summed = {jid: pin.Inertia.Zero() for jid in range(asset.model.njoints)}
    for name, prim in asset.links.items():
        fid = asset.model.getFrameId(name, pin.BODY)
        parent = asset.model.frames[fid].parentJoint
        summed[parent] += asset.data.oMf[fid].act(usd_inertia(prim))
    total = 0.0
    for jid in range(1, asset.model.njoints):
        expected = asset.data.oMi[jid].act(asset.model.inertias[jid])
        got = summed[jid]
        scale = max(1.0, abs(expected.mass))
        assert got.mass == pytest.approx(expected.mass, rel=FLOAT, abs=FLOAT), asset.model.names[jid]
        np.testing.assert_allclose(got.lever * got.mass, expected.lever * expected.mass, atol=FLOAT * scale,
                                   err_msg=asset.model.names[jid])
        big = max(1e-3, float(np.abs(expected.inertia).max()))
        np.testing.assert_allclose(got.inertia, expected.inertia, atol=FLOAT * big, rtol=0,
                                   err_msg=asset.model.names[jid])
        total += got.mass
    assert total == pytest.approx(pin.computeTotalMass(asset.model), rel=FLOAT)


def _pin_axis(joint: pin.JointModel) -> np.ndarray:
    """The joint's axis in its frame: RX, PY, RUBZ…, or an unaligned joint's own."""
    inner = joint.extract()
    if hasattr(inner, "axis"):
        return np.asarray(inner.axis, dtype=float)
    return np.eye(3)["XYZ".index(joint.shortname()[-1])]


def test_every_joints_frame_axis_and_limits_are_pinocchios(asset: Asset) -> None:
    model, data = asset.model, asset.data
    moving = [jid for jid in range(2, model.njoints)]  # not the universe, not the free flyer
    fixed = [f for f in model.frames[1:] if f.type == pin.FIXED_JOINT]  # not the universe
    assert sorted([model.names[j] for j in moving] + [f.name for f in fixed]) == sorted(asset.joints)
    for jid in moving:
        name = model.names[jid]
        prim = asset.joints[name]
        on0, on1 = joint_frames(asset, prim)
        np.testing.assert_allclose(on0, on1, atol=FLOAT, rtol=0, err_msg=name)
        np.testing.assert_allclose(on0[:3, 3], data.oMi[jid].translation, atol=FLOAT, rtol=0, err_msg=name)
        axis = "XYZ".index(prim.GetAttribute("physics:axis").Get())
        pin_axis = data.oMi[jid].rotation @ _pin_axis(model.joints[jid])
        np.testing.assert_allclose(on0[:3, axis], pin_axis / np.linalg.norm(pin_axis), atol=FLOAT,
                                   err_msg=name)
        if model.nqs[jid] != 1:  # continuous: no limits
            assert not prim.GetAttribute("physics:lowerLimit").HasAuthoredValue(), name
            continue
        q = model.idx_qs[jid]
        per = math.pi / 180 if prim.IsA(UsdPhysics.RevoluteJoint) else 1.0
        got = (prim.GetAttribute("physics:lowerLimit").Get() * per,
               prim.GetAttribute("physics:upperLimit").Get() * per)
        assert got == pytest.approx((model.lowerPositionLimit[q], model.upperPositionLimit[q]),
                                    rel=FLOAT, abs=FLOAT), name
    for frame in fixed:
        prim = asset.joints[frame.name]
        assert prim.IsA(UsdPhysics.FixedJoint)
        on0, on1 = joint_frames(asset, prim)
        np.testing.assert_allclose(on0, on1, atol=FLOAT, rtol=0, err_msg=frame.name)
        placed = data.oMf[model.getFrameId(frame.name, pin.FIXED_JOINT)].translation
        np.testing.assert_allclose(on0[:3, 3], placed, atol=FLOAT, rtol=0, err_msg=frame.name)


def test_newton_reads_the_same_masses_inertias_and_limits(assets: dict[str, Asset]) -> None:
    read = newton_reads([a.path for a in assets.values()])
    for asset in assets.values():
        got = read[str(asset.path)]
        bodies = {str(p.GetPath()): name for name, p in asset.links.items()
                  if p.HasAPI(UsdPhysics.RigidBodyAPI)}
        assert sorted(got["bodies"]) == sorted(bodies)
        for path, name in bodies.items():
            inertial = asset.robot.links[name].inertial
            body = got["bodies"][path]
            expected = usd_inertia(asset.links[name])
            if _no_mass(inertial) and asset.robot.links[name].collisions:
                continue  # UsdPhysics computes what is not given from the shapes (W0500 says so)
            assert body["mass"] == pytest.approx(expected.mass, rel=FLOAT), path
            np.testing.assert_allclose(body["com"], expected.lever,
                                       atol=FLOAT * max(1, np.abs(expected.lever).max()), err_msg=path)
            if not expected.inertia.any():
                continue  # a point mass: Newton gives every body an inertia of its own (a floor)
            big = float(np.abs(expected.inertia).max())
            np.testing.assert_allclose(body["inertia"], expected.inertia, atol=10 * FLOAT * big, rtol=0,
                                       err_msg=path)
        joints = {str(p.GetPath()): name for name, p in asset.joints.items()}
        assert set(joints) <= set(got["joints"])
        for path, name in joints.items():
            joint = asset.robot.joints[name]
            if joint.type in ("revolute", "prismatic"):
                assert joint.limit is not None
                assert got["dof_limits"][path] == pytest.approx([joint.limit.lower, joint.limit.upper],
                                                                rel=FLOAT, abs=FLOAT), path
            if joint.type in ("revolute", "continuous", "prismatic") and joint.limit is not None \
                    and joint.limit.velocity is not None:
                assert got["velocity_limits"][path] == pytest.approx(joint.limit.velocity, rel=FLOAT), path


def test_usd_cores_validators_report_nothing(asset: Asset) -> None:
    context = UsdValidation.ValidationContext(UsdValidation.ValidationRegistry().GetOrLoadAllValidators())
    assert [(e.GetName(), e.GetMessage()) for e in context.Validate(asset.stage)] == []
