"""The MJCF backend: every example-robot-data model loads in MuJoCo and is the same robot as
Pinocchio's (mass, link placements, gravity torques), or gives our diagnostic for what
MuJoCo refuses; mimic joints, bitmasks, joint types, cut joints and motors on small cases."""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

from mpc.backends import meshes, mjcf, urdf
from mpc.backends.dae_colours import coloured
from mpc.backends.smurf_forms import named_shapes
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.span import Span
from mpc.ir import transforms as tf
from mpc.ir.bitmask import assign, never_colliding
from mpc.ir.extras import CutJoint, Motor
from mpc.ir.geometry import Box, Cylinder, Mesh, Sphere
from mpc.ir.program import MjcfExport
from mpc.ir.robot import Collision, Inertia, Inertial, Joint, Limit, Link, Mimic, Pose, Robot
from tests.backends.test_urdf_real_models import GOOD
from tests.conftest import ERD, Diags

SPAN = Span("model.yml", 3, 5)
PSYONIC = ("LeftPsyonicAbilityBaseLink", "Left_thumb_base", "RightPsyonicAbilityBaseLink", "Right_thumb_base")
ALLEGRO = ("link_3.0", "link_7.0", "link_11.0", "link_15.0")
TIAGO = ("base_antenna_left_link", "base_antenna_right_link")
ICUB = ("l_ankle_2", "r_hip_1", "r_hip_2", "r_upper_leg", "r_lower_leg", "r_ankle_1", "r_ankle_2",
        "l_wrist_1", "head", "r_wrist_1")
HUMAN_VIRTUAL = tuple(f"{side}_{part}_virtual{n}" for side, part, n in (
    *((s, p, n) for s in ("left", "right") for p in ("upperleg", "upperarm") for n in ("", "_2")),
    *((s, p, "") for s in ("left", "right") for p in ("foot", "lowerarm", "hand")),
    ("middle", "abdomen", ""), ("middle", "thorax", ""), ("middle", "thorax", "_2"),
    ("middle", "head", ""), ("middle", "head", "_2")))
ROMEO_FINGERS = tuple(f"{s}{f}Link" for s in "LR" for f in (
    *(f"Finger{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)), "Thumb1", "Thumb2", "Thumb3"))
DUMMY_BASE = "the dummy base inertia (all six entries 1e-6: principal moments 0, 0, 3e-6)"

# Source inertias MuJoCo refuses: our E0504 names exactly these links, and MuJoCo refuses the
# model (naming one of them, or a mesh of MESH_REFUSED that it reads first).
BAD_INERTIA: dict[str, tuple[str, tuple[str, ...]]] = {
    "alex_description/urdf/alex_psyonic_hands.urdf": ("hand and thumb bases: A + B < C", PSYONIC),
    "allegro_hand_description/urdf/allegro_left_hand.urdf": ("finger bases and thumb tip: A + B < C",
                                                             ALLEGRO),
    "allegro_hand_description/urdf/allegro_right_hand.urdf": ("the same as the left hand", ALLEGRO),
    "anymal_b_simple_description/robots/anymal-kinova.urdf": (DUMMY_BASE, ("base",)),
    "anymal_b_simple_description/robots/anymal.urdf": (DUMMY_BASE, ("base",)),
    "anymal_c_simple_description/urdf/anymal.urdf": (
        "depth cameras (A + B < C) and the hatch (principal moments 0, 0, 0.003)",
        ("depth_camera_front_camera", "depth_camera_rear_camera", "hatch", "depth_camera_left_camera",
         "depth_camera_right_camera")),
    "b1_description/urdf/b1-z1.urdf": (DUMMY_BASE, ("base",)),
    "b1_description/urdf/b1.urdf": (DUMMY_BASE, ("base",)),
    "go1_description/urdf/go1.urdf": (DUMMY_BASE, ("base",)),
    "hyq_description/robots/hyq_no_sensors.urdf": (
        DUMMY_BASE + ", and on the feet", ("base_link", "lf_foot", "lh_foot", "rf_foot", "rh_foot")),
    "icub_description/robots/icub.urdf": (
        "zero inertias (round-off off-diagonal terms) on moving links", (*ICUB, "neck_1", "neck_2")),
    "icub_description/robots/icub_reduced.urdf": ("the same as icub", ICUB),
    "pr2_description/urdf/pr2.urdf": ("sensor mounts: 0.001 + 0.001 < 0.01",
                                      ("sensor_mount_link", "double_stereo_link")),
    "romeo_description/urdf/romeo.urdf": ("massless moving finger links", ROMEO_FINGERS),
    "romeo_description/urdf/romeo_small.urdf": ("arm links: A + B < C",
                                                 ("RShoulderYawLink", "RElbowYawLink")),
    "tiago_description/robots/tiago.urdf": ("antennas: an indefinite inertia matrix", TIAGO),
    "tiago_description/robots/tiago_dual.urdf": ("the same as tiago", TIAGO),
    "tiago_description/robots/tiago_no_hand.urdf": ("the same as tiago", TIAGO),
}
# Meshes MuJoCo would refuse (backends/mujoco_meshes.py): the export says so and writes no MJCF.
# (why, the code, the end of its message)
MESH_REFUSED: dict[str, tuple[str, str, str]] = {
    "b1_description/urdf/b1.urdf": (
        "trunk.dae gives an STL of 250k faces", "E0588",
        "it has 250,639 triangles; MuJoCo reads at most 200,000 from an STL file"),
    "b1_description/urdf/b1-z1.urdf": (
        "trunk.dae gives an STL of 250k faces", "E0588",
        "it has 250,639 triangles; MuJoCo reads at most 200,000 from an STL file"),
    "go1_description/urdf/go1.urdf": (
        "trunk.dae gives an STL of 351k faces", "E0588",
        "it has 351,394 triangles; MuJoCo reads at most 200,000 from an STL file"),
}
# Exported with OBJ meshes, as their own are (alex: several objects in a file, written again
# for MuJoCo as one).
OBJ_EXPORT = {"alex_description/urdf/alex_nub_hands.urdf", "alex_description/urdf/alex_psyonic_hands.urdf",
              "alex_description/urdf/alex_sake_hands.urdf", "quadruped_description/urdf/quadruped.urdf"}


@dataclass
class Emitted:
    robot: Robot
    xml: Path
    namer: Callable[[Mesh], str]
    diagnostics: list[Diagnostic]


@pytest.fixture(scope="module")
def emitted(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, str], Emitted]:
    """Emit each model once per format (mesh conversion is the slow part)."""
    cache: dict[tuple[str, str], Emitted] = {}
    root = tmp_path_factory.mktemp("mjcf")

    def get(model: str, fmt: str = "stl") -> Emitted:
        if (model, fmt) not in cache:
            robot = urdf.read(ERD / model, Sink())
            assert robot is not None
            sink = Sink()
            out = root / fmt / model.replace("/", "_")
            mjcf.emit(robot, MjcfExport(mesh_format=fmt, span=SPAN), out, sink)
            files = meshes.plan(coloured(robot), fmt, Sink(), SPAN, mujoco=True) or {}
            cache[model, fmt] = Emitted(robot, out / "mjcf" / f"{robot.name}.xml",
                                        lambda m: "../" + files[meshes.key(m)], sink.diagnostics)
        return cache[model, fmt]

    return get


def _flagged(diagnostics: list[Diagnostic]) -> list[str]:
    return [re.match(r"link '(.*?)' ", d.message).group(1)  # type: ignore[union-attr]
            for d in diagnostics if d.code == "E0504"]


def _simulate(model: mujoco.MjModel) -> mujoco.MjData:
    """0.1 s with the default timestep; no MuJoCo warning and a finite state."""
    data = mujoco.MjData(model)
    for _ in range(round(0.1 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all() and np.isfinite(data.qacc).all()
    return data


def _assert_same_robot(source: Path, robot: Robot, model: mujoco.MjModel) -> None:
    """Mass with the root link, inertias, link placements and gravity torques at q = 0."""
    free = pin.buildModelFromUrdf(str(source), pin.JointModelFreeFlyer())
    assert abs(mujoco.mj_getTotalmass(model) - pin.computeTotalMass(free)) <= 1e-6
    fixed = pin.buildModelFromUrdf(str(source))
    pdata, data = fixed.createData(), mujoco.MjData(model)
    q = pin.neutral(fixed)
    assert model.nv == fixed.nv
    mujoco.mj_forward(model, data)  # qpos0 is 0 for every hinge and slide, qvel is 0
    gravity = pin.computeGeneralizedGravity(fixed, pdata, q)
    for jid in range(1, fixed.njoints):
        mj = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, fixed.names[jid])
        assert mj >= 0, fixed.names[jid]
        dof = model.jnt_dofadr[mj]
        assert abs(data.qfrc_bias[dof] - gravity[fixed.idx_vs[jid]]) <= 1e-6, fixed.names[jid]
    pin.framesForwardKinematics(fixed, pdata, q)
    for fid, frame in enumerate(fixed.frames):
        if frame.type != pin.FrameType.BODY:
            continue
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, frame.name)
        if body < 0:  # a massless link that passes motion on joined the body below it (human.urdf)
            assert frame.name in HUMAN_VIRTUAL
            continue
        np.testing.assert_allclose(data.xpos[body], pdata.oMf[fid].translation, atol=1e-9)
        np.testing.assert_allclose(data.xmat[body].reshape(3, 3), pdata.oMf[fid].rotation, atol=1e-9)
    for link in robot.links.values():  # the principal frame gives back the source's inertia
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, link.name)
        if link.inertial is None or body <= 0:
            continue
        i, origin = link.inertial.inertia, link.inertial.origin or Pose()
        R_o = tf.rpy_to_matrix(origin.rpy)
        I_L = R_o @ np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]]) @ R_o.T
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, model.body_iquat[body])
        R = R.reshape(3, 3)
        np.testing.assert_allclose(R @ np.diag(model.body_inertia[body]) @ R.T, I_L,
                                   atol=1e-12 + 1e-9 * np.abs(I_L).max(), err_msg=link.name)
        np.testing.assert_allclose(model.body_ipos[body], origin.xyz, atol=1e-15)
        assert model.body_mass[body] == link.inertial.mass


# Models with a DAE mesh whose material references are broken (W0605: read all the same): the
# ANYmal foot's texture was not shipped.
BROKEN_DAE = {"anymal_b_simple_description/robots/anymal.urdf",
              "anymal_b_simple_description/robots/anymal-kinova.urdf"}


def test_the_lists_above_name_real_models() -> None:
    assert set(BAD_INERTIA) | set(MESH_REFUSED) | OBJ_EXPORT <= set(GOOD)
    # the models MuJoCo loads; simple_humanoid among them since its ASCII box.stl is written again
    assert len(set(GOOD) - set(BAD_INERTIA) - set(MESH_REFUSED)) == 49


@pytest.mark.parametrize("model", GOOD)
def test_model_loads_in_mujoco_as_the_same_robot(model: str, emitted: Callable[[str, str], Emitted]) -> None:
    e = emitted(model, "obj" if model in OBJ_EXPORT else "stl")
    codes = sorted(d.code for d in e.diagnostics)
    broken_dae = {"W0605"} if model in BROKEN_DAE else set()
    refused = MESH_REFUSED.get(model)
    allowed = {"W0500", "E0504", *(refused[1:2] if refused else ())}
    messages = [d.message for d in e.diagnostics]
    assert set(codes) - broken_dae <= allowed and codes.count("W0500") <= 1, messages
    assert ("W0605" in codes) == bool(broken_dae)
    if refused is not None:
        assert any(d.code == refused[1] and d.message.endswith(refused[2]) for d in e.diagnostics)
        assert not e.xml.exists()
        return
    # Canonical: the same robot gives the same text, and to_string is what emit wrote (of the
    # robot as emit prepares it: DAE visuals split by material, its unnamed shapes named as the
    # SMURF names them).
    assert mjcf.to_string(named_shapes(coloured(e.robot)), e.namer) == e.xml.read_text()
    flagged = _flagged(e.diagnostics)
    assert sorted(flagged) == sorted(BAD_INERTIA.get(model, ("", ()))[1])
    try:
        compiled = mujoco.MjModel.from_xml_path(str(e.xml))
    except ValueError as refusal:  # MuJoCo names the first body it refuses: one our diagnostic named before
        assert model in BAD_INERTIA
        assert re.search(r"Element name '(.*?)'", str(refusal)).group(1) in flagged  # type: ignore[union-attr]
        return
    assert model not in BAD_INERTIA
    _simulate(compiled)
    _assert_same_robot(ERD / model, e.robot, compiled)


def test_a_model_of_an_ascii_stl_loads_with_obj_meshes(tmp_path: Path) -> None:
    """simple_humanoid (its box.stl is an ASCII STL, which MuJoCo's STL reader refuses) as OBJ."""
    source = ERD / "simple_humanoid_description/urdf/simple_humanoid.urdf"
    robot = urdf.read(source, Sink())
    assert robot is not None
    sink = Diags()
    mjcf.emit(robot, MjcfExport(mesh_format="obj", span=SPAN), tmp_path, sink)
    sink.take("W0500", Severity.WARNING)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "mjcf" / f"{robot.name}.xml"))
    _simulate(model)
    _assert_same_robot(source, robot, model)


def test_emitting_twice_gives_identical_bytes(tmp_path: Path, emitted: Callable[[str, str], Emitted]) -> None:
    """panda: DAE visuals converted to STL, full inertias diagonalised, a mimic joint."""
    first = emitted("panda_description/urdf/panda.urdf").xml.parent.parent
    robot = urdf.read(ERD / "panda_description/urdf/panda.urdf", Sink())
    assert robot is not None
    mjcf.emit(robot, MjcfExport(mesh_format="stl", span=SPAN), tmp_path, Sink())

    def files(root: Path) -> dict[str, bytes]:
        return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}

    a, b = files(first), files(tmp_path)
    assert len(a) == 35 and a == b  # the MJCF and 34 meshes (DAE visuals split by material)


def test_mimic_is_a_joint_equality_with_mujocos_convention(tmp_path: Path) -> None:
    """joint1 = offset + multiplier · joint2: checked on the constraint's residual."""
    robot = urdf.read(ERD / "panda_description/urdf/panda.urdf", Sink())
    assert robot is not None
    text = mjcf.to_string(robot, lambda m: m.source.uri)
    eq = etree.fromstring(text.encode()).find("equality/joint")
    assert dict(eq.attrib) == {"joint1": "panda_finger_joint2", "joint2": "panda_finger_joint1",
                               "polycoef": "0 1 0 0 0"}
    joints = dict(robot.joints)
    mimic = Mimic(joint="panda_finger_joint1", multiplier=2.0, offset=0.1)
    joints["panda_finger_joint2"] = replace(joints["panda_finger_joint2"], mimic=mimic)
    bare = {n: replace(lk, visuals=(), collisions=()) for n, lk in robot.links.items()}
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(replace(robot, links=bare, joints=joints), str))
    data = mujoco.MjData(model)
    for follower, residual in ((0.1 + 2 * 0.01, 0.0), (0.0, -0.12)):
        data.qpos[model.joint("panda_finger_joint1").qposadr] = 0.01
        data.qpos[model.joint("panda_finger_joint2").qposadr] = follower
        mujoco.mj_forward(model, data)
        rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        np.testing.assert_allclose(data.efc_pos[rows], [residual], atol=1e-15)


def test_collision_bitmasks_become_contype_and_conaffinity(emitted: Callable[[str, str], Emitted]) -> None:
    """a1 with Phobos-style bitmasks: MuJoCo's (contype1 & conaffinity2) | (contype2 &
    conaffinity1) is then the bitmask rule (mask1 & mask2)."""
    e = emitted("a1_description/urdf/a1.urdf")
    robot = e.robot
    with_shapes = sorted(n for n, lk in robot.links.items() if lk.collisions)
    allowed = {frozenset(p) for p in itertools.combinations(with_shapes, 2)} - never_colliding(robot)
    masks, _ = assign(with_shapes, allowed)
    assert len(set(masks.values())) > 2
    links = {n: replace(lk, collisions=tuple(replace(c, bitmask=masks[n]) for c in lk.collisions))
             for n, lk in robot.links.items()}
    xml = e.xml.with_name("a1_bitmasks.xml")
    xml.write_text(mjcf.to_string(replace(robot, links=links), e.namer))
    model = mujoco.MjModel.from_xml_path(str(xml))
    checked = 0
    for g in range(model.ngeom):
        name = model.body(model.geom_bodyid[g]).name
        if model.geom_group[g] == 3:
            assert model.geom_contype[g] == model.geom_conaffinity[g] == masks[name]
            checked += 1
        else:
            assert (model.geom_group[g], model.geom_contype[g], model.geom_conaffinity[g]) == (2, 0, 0)
    assert checked == sum(len(lk.collisions) for lk in robot.links.values())


def test_what_mjcf_cannot_hold_is_one_warning(emitted: Callable[[str, str], Emitted]) -> None:
    e = emitted("talos_data/robots/talos_full_v2.urdf")
    [warning] = e.diagnostics
    assert (warning.code, warning.severity, warning.span) == ("W0500", Severity.WARNING, SPAN)
    assert warning.message == ("the MJCF leaves out what it cannot hold: 44 joint velocity limits, "
                               "110 <gazebo> elements, 28 <transmission> elements")


def test_dae_meshes_are_refused(tmp_path: Path, diags: Diags) -> None:
    robot = _toy()
    mjcf.emit(robot, MjcfExport(mesh_format="dae", span=SPAN), tmp_path, diags)
    assert diags.take_error("E0501").message == "MuJoCo reads no 'dae' meshes"
    assert not tmp_path.joinpath("mjcf").exists()


# --- small robots built in the IR -------------------------------------------------------

def _inertial(mass: float = 1.0, d: tuple[float, float, float] = (0.1, 0.1, 0.1)) -> Inertial:
    return Inertial(mass=mass, inertia=Inertia(ixx=d[0], ixy=0.0, ixz=0.0, iyy=d[1], iyz=0.0, izz=d[2]))


def _toy(**links: Link) -> Robot:
    """base → (slider, prismatic) → (arm, revolute) → (wheel, continuous); base → (drone,
    floating); arm → (puck, planar); base → (cam, fixed); arm → (pod, floating)."""
    spec = [("slide", "prismatic", "base", "slider", (0.0, 0.0, 1.0)),
            ("shoulder", "revolute", "slider", "arm", (0.0, 1.0, 0.0)),
            ("spin", "continuous", "arm", "wheel", (1.0, 0.0, 0.0)),
            ("fly", "floating", "base", "drone", None), ("glide", "planar", "arm", "puck", (0.0, 0.0, 1.0)),
            ("mount", "fixed", "base", "cam", None), ("hover", "floating", "arm", "pod", None)]
    joints = {name: Joint(name=name, type=kind, parent=p, child=c, axis=axis,  # type: ignore[arg-type]
                          origin=Pose((0.1, 0.2, 0.3), (0.3, -0.2, 0.1)),
                          limit=Limit(lower=-1.0, upper=1.0, effort=5.0, velocity=2.0)
                          if kind in ("revolute", "prismatic") else None)
              for name, kind, p, c, axis in spec}
    shapes = (Collision(geometry=Box(size=(0.2, 0.4, 0.6))),
              Collision(geometry=Cylinder(radius=0.1, length=0.5)),
              Collision(geometry=Sphere(radius=0.05), origin=Pose((0.0, 0.0, 0.1), (0.0, 0.0, 0.0))))
    default = {n: Link(name=n, inertial=_inertial(), collisions=shapes if n == "arm" else ())
               for n in ("base", "slider", "arm", "wheel", "drone", "puck", "cam", "pod")}
    return Robot(name="toy", root="base", links={**default, **links}, joints=joints)


def _quat(yaw: float) -> list[float]:
    return [np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]


def test_joint_types_cut_joints_and_motors() -> None:
    robot = replace(_toy(), motors={"shoulder_motor": Motor(name="shoulder_motor", joint="shoulder")},
                    cut_joints={"loop": CutJoint(name="loop", type="revolute", parent="base", child="wheel",
                                                 origin=Pose((0.3, 0.0, 0.0), (0.0, 0.0, 0.0))),
                                "weld": CutJoint(name="weld", type="fixed", parent="cam", child="puck",
                                                 origin=Pose((0.0, 0.1, 0.0), (0.0, 0.0, 0.5)))})
    sink = Diags()
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str, sink))
    assert "1 rotational cut joint's axis (without one, a connect is a ball joint)" in sink.take(
        "W0500", Severity.WARNING).message
    kinds = {model.joint(j).name: int(model.jnt_type[j]) for j in range(model.njnt)}
    T = mujoco.mjtJoint
    assert kinds == {"slide": T.mjJNT_SLIDE, "shoulder": T.mjJNT_HINGE, "spin": T.mjJNT_HINGE,
                     "glide_x": T.mjJNT_SLIDE, "glide_y": T.mjJNT_SLIDE, "glide_rot": T.mjJNT_HINGE,
                     "hover_x": T.mjJNT_SLIDE, "hover_y": T.mjJNT_SLIDE, "hover_z": T.mjJNT_SLIDE,
                     "hover_rot": T.mjJNT_BALL, "fly": T.mjJNT_FREE}
    assert model.body("drone").parentid == 0  # a free joint's body is hoisted to the world
    assert model.nbody == 9 and model.body("cam").jntnum == 0  # welded, not fused
    assert model.nq == 1 + 1 + 3 + 1 + (3 + 4) + 7
    assert {model.joint(j).name for j in range(model.njnt) if model.jnt_limited[j]} == {"slide", "shoulder"}
    assert list(model.eq_type) == [mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD]
    # between sites: the closure's frame on the parent (its origin) and on the child (identity)
    assert list(model.eq_objtype) == [mujoco.mjtObj.mjOBJ_SITE] * 2
    assert [model.site(int(i)).name for i in (*model.eq_obj1id, *model.eq_obj2id)] == \
        ["loop_parent", "weld_parent", "loop_child", "weld_child"]
    np.testing.assert_allclose(model.site("loop_parent").pos, [0.3, 0, 0])
    np.testing.assert_allclose(model.site("loop_child").pos, [0, 0, 0])
    np.testing.assert_allclose(model.site("weld_parent").quat, _quat(0.5), atol=1e-15)
    np.testing.assert_allclose(model.actuator_ctrlrange[0], [-1, 1])  # a position servo (Phobos's default)
    np.testing.assert_allclose(model.actuator_forcerange[0], [-5, 5])
    arm = model.body("arm").id
    sizes = [model.geom_size[g] for g in range(model.ngeom) if model.geom_bodyid[g] == arm]
    np.testing.assert_allclose(sizes, [[0.1, 0.2, 0.3], [0.1, 0.25, 0], [0.05, 0, 0]])
    _simulate(model)
    # Body placements at q = 0 are the joint origins (q = 0 of the free joint is its origin).
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    X = tf.pose_to_matrix((0.1, 0.2, 0.3), (0.3, -0.2, 0.1))
    np.testing.assert_allclose(data.xmat[model.body("slider").id].reshape(3, 3), X[:3, :3], atol=1e-15)
    np.testing.assert_allclose(data.xpos[model.body("arm").id], (X @ X)[:3, 3], atol=1e-15)


@pytest.mark.parametrize(("case", "link", "rule", "loads"), [
    ("negative mass on a welded link", _inertial(mass=-1.0), "mass -1 is negative", True),
    ("A + B < C on a welded link", _inertial(d=(0.1, 0.1, 0.3)), "violate A + B ≥ C", False),
    ("massless moving link", Link(name="wheel"), "moves but its mass", False),
    ("indefinite inertia", Inertial(mass=1.0, inertia=Inertia(ixx=0.1, ixy=0.2, ixz=0.0, iyy=0.1, iyz=0.0,
                                                              izz=0.1)), "not positive semi-definite", False),
])
def test_inertia_mujoco_refuses_or_changes_is_e0504(case: str, link: Link | Inertial, rule: str,
                                                     loads: bool, diags: Diags) -> None:
    name = "cam" if case.endswith("welded link") else "wheel"
    target = link if isinstance(link, Link) else Link(name=name, inertial=link)
    robot = _toy(**{name: target})
    text = mjcf.to_string(robot, str, diags)
    error = diags.take_error("E0504")
    assert error.message.startswith(f"link '{name}' has mass properties MuJoCo refuses or changes: ")
    assert rule in error.message
    diags.take("W0500", Severity.WARNING)
    if loads:  # MuJoCo would have clamped the mass to 0 without a word
        assert mujoco.MjModel.from_xml_string(text).body(name).mass[0] == 0
    else:
        with pytest.raises(ValueError, match=f"Element name '{name}'"):
            mujoco.MjModel.from_xml_string(text)


def test_a_massless_moving_link_with_a_welded_mass_is_fine(diags: Diags) -> None:
    """MuJoCo accepts a moving body whose mass hangs on a welded (fixed) child."""
    robot = _toy(wheel=Link(name="wheel"), tip=Link(name="tip", inertial=_inertial()))
    robot = replace(robot, joints={**robot.joints, "tip": Joint(name="tip", type="fixed", parent="wheel",
                                                                child="tip")})
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str, diags))
    diags.take("W0500", Severity.WARNING)
    _simulate(model)
