"""Simulation-ready MJCF (issue 31, point 3), as Menagerie's policy asks: the compiled output
of example-robot-data's UR5 (multi-material DAE visuals), TALOS and Panda (multi-material DAE
visuals) loads in MuJoCo without a word, steps 1 s from every keyframe without NaN or warning,
its position actuators track a target, its DAE materials' colours are the geoms' and are drawn;
contacts allowed exactly as the bitmasks say; motors become the actuators their types name."""

from __future__ import annotations

import itertools
import os
import textwrap
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from lxml import etree

from mpc.backends import mjcf, urdf
from mpc.backends.mjcf_contacts import rigid_bodies
from mpc.compiler.driver import Options, compile_model
from mpc.core.collada import material_colours
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.bitmask import assign, never_colliding
from mpc.ir.extras import Motor
from mpc.ir.geometry import Sphere
from mpc.ir.robot import Material, Robot, Visual
from tests.backends.test_mjcf import _toy
from tests.backends.test_render_materials import share, two_material_dae
from tests.conftest import ERD, Diags, write

UR5 = "ur_description/urdf/ur5_robot.urdf"
TALOS = "talos_data/robots/talos_full_v2.urdf"
PANDA = "panda_description/urdf/panda.urdf"
POSES = {UR5: {"home": {"shoulder_lift_joint": -1.2, "elbow_joint": 1.5}, "up": {"wrist_1_joint": 0.4}},
         TALOS: {"bent": {"leg_left_4_joint": 0.6, "leg_right_4_joint": 0.6, "arm_left_4_joint": -0.8,
                          "arm_right_4_joint": -0.8}},
         PANDA: {"ready": {"panda_joint4": -2.0, "panda_joint6": 1.6, "panda_joint7": 0.8}}}


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", os.environ.get("MPC_TEST_MESH_CACHE", str(tmp_path / "cache")))


def _compile(tmp_path: Path, model: str) -> tuple[Path, list[str]]:
    """The model through `mpc compile`: auto_bitmask, its poses, an mjcf export with position
    actuators and a scene; the MJCF's path and the diagnostics' codes."""
    poses = "".join(f"\n    {name}: {{{', '.join(f'{j}: {v}' for j, v in q.items())}}}"
                    for name, q in POSES[model].items())
    path = write(tmp_path / "robot.yml", textwrap.dedent(f"""\
        model:
          robotname: robot
          modelname: robot-model
          input_models:
            base:
              basefile: "{ERD / model}"
          assemble:
            model: base
          collisions:
            auto_bitmask: true
          export_config:
            - type: mjcf
              mesh_format: stl
              actuators: position
              scene: true
        """) + textwrap.indent(f"poses:{poses}\n", "  "))
    sink = Sink()
    compile_model(path, sink, Options(out=tmp_path / "out"))
    assert not sink.has_errors(), [d.message for d in sink.diagnostics]
    return tmp_path / "out" / "mjcf" / "robot.xml", [d.code for d in sink.diagnostics]


def _load_quietly(path: Path, capfd: pytest.CaptureFixture[str]) -> mujoco.MjModel:
    """The model MuJoCo compiles, with nothing printed (MuJoCo prints its warnings) and no
    MUJOCO_LOG.TXT written."""
    capfd.readouterr()
    model = mujoco.MjModel.from_xml_path(str(path))
    out, err = capfd.readouterr()
    assert (out, err) == ("", "")
    assert not Path("MUJOCO_LOG.TXT").exists()
    return model


def _step_one_second(model: mujoco.MjModel, key: int) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, key)
    for _ in range(round(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all() and np.isfinite(data.qacc).all()
    return data


@pytest.mark.parametrize("model", [UR5, TALOS, PANDA])
def test_menagerie_policy(model: str, tmp_path: Path, capfd: pytest.CaptureFixture[str],
                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    xml, codes = _compile(tmp_path, model)
    # W0304: 16 bits cannot let every allowed pair of TALOS's collide (the pairs left over never do)
    assert set(codes) <= {"W0500", "W0304"}
    compiled = _load_quietly(xml, capfd)
    assert compiled.nkey == len(POSES[model]) and compiled.nu > 0
    for k, (name, pose) in enumerate(POSES[model].items()):
        assert compiled.key(k).name == name
        for joint, value in pose.items():
            assert compiled.key_qpos[k][compiled.joint(joint).qposadr[0]] == value
            assert compiled.key_ctrl[k][compiled.actuator(joint).id] == value
        data = _step_one_second(compiled, k)
        # Held in its pose: each actuated joint within 0.05 rad of its target after 1 s.
        for a in range(compiled.nu):
            q = data.qpos[compiled.jnt_qposadr[compiled.actuator_trnid[a, 0]]]
            assert abs(q - compiled.key_ctrl[k][a]) < 0.05, compiled.actuator(a).name
    # The scene: the robot, a floor, a light, a sky; it steps too.
    scene = _load_quietly(xml.with_name("robot_scene.xml"), capfd)
    assert (scene.nbody, scene.ngeom - compiled.ngeom, scene.nlight, scene.ntex) == (
        compiled.nbody, 1, 1, 2)
    floor = scene.geom("floor")
    assert floor.type == mujoco.mjtGeom.mjGEOM_PLANE
    # The floor under the lowest collision shape at q0: UR5's wrist (stretched out, it hangs
    # 4.85 cm below the base's origin), TALOS's feet about 1.1 m below its pelvis (its root,
    # fixed), Panda's base link just below its origin.
    low, high = {UR5: (-0.049, -0.048), TALOS: (-1.2, -1.0), PANDA: (-1e-3, 0.0)}[model]
    assert low <= floor.pos[2] <= high
    data = mujoco.MjData(scene)
    mujoco.mj_kinematics(scene, data)
    lowest = min((data.geom_xpos[g] - scene.geom_rbound[g])[2] for g in range(scene.ngeom)
                 if scene.geom_group[g] == 3)
    assert lowest <= floor.pos[2]  # (a bounding sphere reaches lower than the shape)
    _step_one_second(scene, 0)


def _flat_robot(folder: Path, mass: str = "") -> Path:
    """A robot whose base has a visual mesh of one triangle, and a link of `mass` below it."""
    import struct

    (folder / "flat.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 1)
                                      + struct.pack("<12fH", 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0))
    visual = '<visual><geometry><mesh filename="flat.stl"/></geometry></visual>'
    inertial = f'<inertial><mass value="{mass}"/><inertia ixx="{mass}" ixy="0" ixz="0" iyy="{mass}" ' \
        f'iyz="0" izz="{mass}"/></inertial>'
    write(folder / "flat.urdf", f"""<robot name="flat">
  <link name="base">{visual if not mass else ""}</link>
  <link name="arm">{inertial if mass else ""}</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""")
    return write(folder / "flat.yml", """\
        model:
          robotname: flat
          modelname: flat
          input_models: {base: {basefile: flat.urdf}}
          assemble: {model: base}
          export_config:
            - type: mjcf
              mesh_format: stl
              scene: true
        """)


def test_a_scene_of_a_robot_mujoco_refuses_is_e0696(tmp_path: Path) -> None:
    """A moving link of 1e-30 kg: E0504 says MuJoCo refuses it, and the scene, which loads the
    robot in MuJoCo to place its floor, cannot."""
    sink = Diags()
    compile_model(_flat_robot(tmp_path, "1e-30"), sink, Options(out=tmp_path / "out"))
    sink.take_error("E0504")
    error = sink.take_error("E0696")
    assert error.message.startswith("MuJoCo refuses the MJCF of robot 'flat', so its scene cannot place "
                                    "the floor: Error: mass and inertia of moving bodies must be larger "
                                    "than mjMINVAL")
    assert (error.span.line, error.span.col) == (7, 7)  # the entry
    assert not (tmp_path / "out").exists()  # the build failed: nothing is written


def test_a_mesh_mujoco_refuses_is_said_before_the_scene_loads_it(tmp_path: Path) -> None:
    """A visual mesh of one triangle (MuJoCo wants 4 vertices at least): E0585, the file is not
    written, and the scene does not try MuJoCo with it."""
    sink = Diags()
    compile_model(_flat_robot(tmp_path), sink, Options(out=tmp_path / "out"))
    error = sink.take_error("E0585")
    assert error.message == (f"mesh '{tmp_path}/flat.stl' of a visual of link 'base' cannot be copied into "
                             "the build: it has 3 vertices; MuJoCo reads a mesh of 4 or more")
    assert not any(d.code == "E0696" for d in sink.diagnostics)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("model", [UR5, PANDA])
def test_position_actuators_track_a_target(model: str, tmp_path: Path) -> None:
    """Each actuated joint moved 0.3 rad (the finger 1 cm) from the keyframe reaches it within 1 %
    in 4 s, without gravity (a PD servo holds a load with an offset: load / kp)."""
    xml, _ = _compile(tmp_path, model)
    compiled = mujoco.MjModel.from_xml_path(str(xml))
    compiled.opt.gravity[:] = 0
    data = mujoco.MjData(compiled)
    mujoco.mj_resetDataKeyframe(compiled, data, 0)
    start = data.qpos.copy()
    for a in range(compiled.nu):
        j = compiled.actuator_trnid[a, 0]
        step = 0.01 if compiled.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE else 0.3
        lo, hi = compiled.actuator_ctrlrange[a]
        data.ctrl[a] = np.clip(start[compiled.jnt_qposadr[j]] + step, lo, hi)
    for _ in range(round(4.0 / compiled.opt.timestep)):
        mujoco.mj_step(compiled, data)
    for a in range(compiled.nu):
        j = compiled.actuator_trnid[a, 0]
        moved = data.qpos[compiled.jnt_qposadr[j]] - start[compiled.jnt_qposadr[j]]
        wanted = data.ctrl[a] - start[compiled.jnt_qposadr[j]]
        assert abs(moved - wanted) <= 0.01 * abs(wanted), compiled.actuator(a).name


def test_dae_materials_are_split_meshes_with_their_colours(tmp_path: Path) -> None:
    """UR5's visuals are DAE files of 2 to 4 materials: one geom and one mesh file per material,
    each with its material's colour (MuJoCo's compiled mat_rgba), the meshes in meshes/stl/."""
    xml, _ = _compile(tmp_path, UR5)
    compiled = mujoco.MjModel.from_xml_path(str(xml))
    robot = urdf.read(ERD / UR5, Sink())
    assert robot is not None
    checked = 0
    for link in robot.links.values():
        for visual in link.visuals:
            colours = material_colours(visual.geometry.source.path)  # type: ignore[union-attr]
            body = compiled.body(link.name).id
            geoms = [g for g in range(compiled.ngeom) if compiled.geom_bodyid[g] == body
                     and compiled.geom_group[g] == 2]
            assert len(geoms) == len(colours) >= 2
            for g, colour in zip(geoms, colours, strict=True):
                assert compiled.geom_matid[g] >= 0
                np.testing.assert_allclose(compiled.mat_rgba[compiled.geom_matid[g]], colour, atol=1e-6)
                checked += 1
    assert checked == 20
    stems = sorted(p.name for p in (tmp_path / "out" / "meshes" / "stl").glob("upperarm_material*.stl"))
    assert stems == [f"upperarm_material{i}.stl" for i in range(4)]


def test_dae_colours_are_drawn(tmp_path: Path) -> None:
    """A DAE file of a red and a blue box (the file the render tests write) through an mjcf
    export: the exported file, drawn by MuJoCo (the render export's renderer), shows both."""
    from mpc.backends.scene import Scene, frame

    two_material_dae(tmp_path / "meshes/boxes.dae")
    write(tmp_path / "boxes.urdf", """<robot name="boxes">
  <link name="base"><visual><geometry><mesh filename="meshes/boxes.dae"/></geometry></visual></link>
</robot>
""")
    definition = write(tmp_path / "boxes.yml", """\
        model:
          robotname: boxes
          modelname: boxes
          input_models: {base: {basefile: boxes.urdf}}
          assemble: {model: base}
          export_config:
            - type: mjcf
        """)
    sink = Sink()
    compile_model(definition, sink, Options(out=tmp_path / "out"))
    assert not sink.diagnostics, [d.message for d in sink.diagnostics]
    compiled = mujoco.MjModel.from_xml_path(str(tmp_path / "out/mjcf/boxes.xml"))
    np.testing.assert_array_equal(compiled.mat_rgba[compiled.geom_matid], [[1, 0, 0, 1], [0, 0, 1, 1]])
    assert sorted(p.name for p in (tmp_path / "out/meshes/obj").iterdir()) == [
        "boxes_material0.obj", "boxes_material1.obj"]
    scene = Scene(compiled, "visual")
    scene.pose({})
    try:
        rgb = scene.draw(frame(scene.points(), "front", (160, 120)), (160, 120)).astype(int)
    finally:
        scene.close()
    left, right = rgb[:, :80], rgb[:, 80:]  # seen from the front (from +x), -y is on the left
    assert share(left, 0) > 0.1 and share(left, 2) == 0
    assert share(right, 2) > 0.1 and share(right, 0) == 0


def _colliding_pairs(robot: Robot) -> set[frozenset[str]]:
    """The pairs of links MuJoCo finds in contact when every collision is a sphere of 5 m
    at its link's origin (so every shape overlaps every other)."""
    links = {n: replace(lk, visuals=(), collisions=tuple(replace(c, geometry=Sphere(radius=5.0), origin=None)
                                                         for c in lk.collisions))
             for n, lk in robot.links.items()}
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(replace(robot, links=links), str))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body = [model.body(model.geom_bodyid[g]).name for g in range(model.ngeom)]
    return {frozenset((body[c.geom1], body[c.geom2])) for c in data.contact[:data.ncon]}


def _pairs(robot: Robot) -> set[frozenset[str]]:
    """Pairs of links with collisions in different rigid bodies (MuJoCo never collides one
    rigid body with itself)."""
    group = rigid_bodies(robot)
    shaped = sorted(n for n, lk in robot.links.items() if lk.collisions)
    return {frozenset(p) for p in itertools.combinations(shaped, 2) if group[p[0]] != group[p[1]]}


def test_allowed_pairs_are_exactly_the_bitmasks() -> None:
    """TALOS with auto_bitmask's masks: MuJoCo collides exactly the pairs whose masks share a bit."""
    robot = urdf.read(ERD / TALOS, Sink())
    assert robot is not None
    shaped = sorted(n for n, lk in robot.links.items() if lk.collisions)
    allowed = {frozenset(p) for p in itertools.combinations(shaped, 2)} - never_colliding(robot)
    masks, _ = assign(shaped, allowed)
    links = {n: replace(lk, collisions=tuple(replace(c, bitmask=masks[n]) for c in lk.collisions))
             for n, lk in robot.links.items()}
    robot = replace(robot, links=links)
    wanted = {p for p in _pairs(robot) if (lambda a, b: masks[a] & masks[b])(*sorted(p))}
    assert len(wanted) > 300
    assert _colliding_pairs(robot) == wanted
    # A parent and child whose masks share a bit collide too: the bitmasks decide, not MuJoCo's
    # parent filter (disabled).
    ones = {n: replace(lk, collisions=tuple(replace(c, bitmask=1) for c in lk.collisions))
            for n, lk in robot.links.items()}
    robot2 = replace(robot, links=ones)
    assert _colliding_pairs(robot2) == _pairs(robot2)


def test_without_bitmasks_links_joined_by_a_joint_do_not_collide() -> None:
    """UR5 without bitmasks: every pair of rigid bodies collides except those a joint joins
    (the base welded to the world and the shoulder included; ee_link welded to wrist 3)."""
    robot = urdf.read(ERD / UR5, Sink())
    assert robot is not None
    group = rigid_bodies(robot)
    jointed = {frozenset((group[j.parent], group[j.child])) for j in robot.joints.values()
               if j.type != "fixed"}
    wanted = {p for p in _pairs(robot) if frozenset(group[x] for x in p) not in jointed}
    assert frozenset(("base_link", "shoulder_link")) not in wanted
    assert frozenset(("wrist_2_link", "ee_link")) not in wanted
    assert frozenset(("base_link", "upper_arm_link")) in wanted
    assert _colliding_pairs(robot) == wanted


def test_motors_become_the_actuators_their_types_name(diags: Diags) -> None:
    motors = {"a_pos": Motor(name="a_pos", joint="shoulder", settings={"p": 50.0, "d": 2.0, "i": 0.0}),
              "b_vel": Motor(name="b_vel", joint="slide", settings={"type": "velocity", "p": 3.0}),
              "c_torque": Motor(name="c_torque", joint="spin", settings={"type": "torque", "i": 0.5}),
              "d_odd": Motor(name="d_odd", joint="spin", settings={"type": "hydraulic"})}
    robot = replace(_toy(), motors=motors)
    text = mjcf.to_string(robot, str, diags)
    assert diags.take("W0500", Severity.WARNING).message == (
        "the MJCF leaves out what it cannot hold: 2 joint velocity limits, 1 motor setting, motor "
        "'d_odd' of type 'hydraulic' (MuJoCo has no actuator for it; position, velocity and "
        "force/effort/torque it has)")  # the setting: c_torque's i (a_pos's i is 0)
    root = etree.fromstring(text.encode())
    assert [(e.tag, dict(e.attrib)) for e in root.find("actuator")] == [
        ("velocity", {"name": "b_vel", "joint": "slide", "kv": "3", "ctrlrange": "-2 2",
                      "forcerange": "-5 5"}),
        ("position", {"name": "a_pos", "joint": "shoulder", "kp": "50", "kv": "2", "ctrlrange": "-1 1",
                      "forcerange": "-5 5"}),
        ("motor", {"name": "c_torque", "joint": "spin"})]
    model = mujoco.MjModel.from_xml_string(text)
    pos = model.actuator("a_pos")
    assert (pos.gainprm[0], pos.biasprm[1], pos.biasprm[2]) == (50, -50, -2)
    vel = model.actuator("b_vel")
    assert (vel.gainprm[0], vel.biasprm[2]) == (3, -3)
    assert model.actuator("c_torque").gainprm[0] == 1 and not model.actuator_ctrllimited[2]


@pytest.mark.parametrize(("mode", "tags"), [
    ("motors", ["position"]), ("position", ["position"] * 3),
    ("velocity", ["velocity", "position", "velocity"]), ("motor", ["motor", "position", "motor"]),
    ("none", [])])
def test_the_actuators_option_drives_the_joints_without_a_motor(mode: str, tags: list[str]) -> None:
    """slide, shoulder (its motor) and spin, in depth-first order; gains from the effort limit."""
    robot = replace(_toy(), motors={"m": Motor(name="m", joint="shoulder")})
    root = etree.fromstring(mjcf.to_string(robot, str, actuators=mode).encode())
    acts = root.find("actuator")
    assert ([e.tag for e in acts] if acts is not None else []) == tags
    if mode == "position":
        assert dict(acts[0].attrib) == {"name": "slide", "joint": "slide", "kp": "50", "dampratio": "1",
                                        "ctrlrange": "-1 1", "forcerange": "-5 5"}
        model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str, actuators=mode))
        assert model.actuator("spin").ctrllimited == 0  # continuous: no range


def test_a_mimic_follower_gets_no_actuator_and_keyframes_follow_its_leader() -> None:
    robot = urdf.read(ERD / PANDA, Sink())
    assert robot is not None
    robot = replace(robot, poses={"open": {"panda_finger_joint1": 0.03}})
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(_bare(robot), str, actuators="position"))
    names = [model.actuator(a).name for a in range(model.nu)]
    assert "panda_finger_joint1" in names and "panda_finger_joint2" not in names
    assert model.key_qpos[0][model.joint("panda_finger_joint2").qposadr[0]] == 0.03


def _bare(robot: Robot) -> Robot:
    return replace(robot, links={n: replace(lk, visuals=(), collisions=()) for n, lk in robot.links.items()})


def test_keyframes_hold_a_free_joint_and_planar_joints() -> None:
    """The toy's qpos: slide, shoulder, spin, planar (3), floating below the arm (3 + 4), the
    hoisted free joint (7) at its origin."""
    robot = replace(_toy(), poses={"p": {"shoulder": 0.5, "spin": -1.0, "fly": 2.0}})
    sink = Diags()
    text = mjcf.to_string(robot, str, sink, actuators="position")
    warning = sink.take("W0500", Severity.WARNING).message
    assert "1 pose value of a joint without one degree of freedom" in warning
    model = mujoco.MjModel.from_xml_string(text)
    key = model.key("p")
    qpos = np.array(key.qpos)
    assert qpos[model.joint("shoulder").qposadr[0]] == 0.5 and qpos[model.joint("spin").qposadr[0]] == -1.0
    free = model.joint("fly").qposadr[0]
    np.testing.assert_allclose(qpos[free:free + 3], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(qpos[free + 3:free + 7], model.body("drone").quat)
    np.testing.assert_allclose(qpos[model.joint("hover_rot").qposadr[0]:][:4], [1, 0, 0, 0])
    assert list(key.ctrl) == [0.0, 0.5, -1.0]
    _step_in_place(model)


def _step_in_place(model: mujoco.MjModel) -> None:
    for k in range(model.nkey):
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, k)
        for _ in range(100):
            mujoco.mj_step(model, data)
        assert [w.number for w in data.warning] == [0] * len(data.warning)


def test_visuals_are_group_2_and_never_collide_collisions_group_3() -> None:
    robot = _toy()
    links = dict(robot.links)
    links["arm"] = replace(links["arm"], visuals=(Visual(geometry=Sphere(radius=0.1), material="red"),))
    robot = replace(robot, links=links, materials={"red": Material(name="red", rgba=(1.0, 0.0, 0.0, 1.0))})
    model = mujoco.MjModel.from_xml_string(mjcf.to_string(robot, str))
    groups = {(int(model.geom_group[g]), int(model.geom_contype[g]), int(model.geom_conaffinity[g]))
              for g in range(model.ngeom)}
    assert groups == {(2, 0, 0), (3, 1, 1)}
    visual = next(g for g in range(model.ngeom) if model.geom_group[g] == 2)
    assert model.material(int(model.geom_matid[visual])).name == "red"
    np.testing.assert_allclose(model.mat_rgba[model.geom_matid[visual]], [1, 0, 0, 1])


def test_output_is_byte_stable(tmp_path: Path) -> None:
    first, _ = _compile(tmp_path / "a", UR5)
    second, _ = _compile(tmp_path / "b", UR5)

    def files(root: Path) -> dict[str, bytes]:
        return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}

    a, b = files(first.parent.parent), files(second.parent.parent)
    assert a == b and "mjcf/robot_scene.xml" in a


def test_motors_mjcf_cannot_drive_are_named_in_w0500(diags: Diags) -> None:
    robot = replace(_toy(), motors={"m": Motor(name="m", joint="fly", settings={"p": 1.0}),
                                    "n": Motor(name="n", joint="shoulder")})
    mjcf.to_string(robot, str, diags)
    assert "1 motor of a joint without one degree of freedom" in diags.take("W0500", Severity.WARNING).message
    text = mjcf.to_string(robot, str, diags, actuators="none")
    assert "2 motors (actuators: none)" in diags.take("W0500", Severity.WARNING).message
    assert "<actuator>" not in text


def test_an_unknown_actuators_value_is_refused(tmp_path: Path) -> None:
    definition = write(tmp_path / "robot.yml", f"""\
        model:
          robotname: robot
          modelname: robot
          input_models: {{base: {{basefile: "{ERD / UR5}"}}}}
          assemble: {{model: base}}
          export_config:
            - type: mjcf
              actuators: positoin
        """)
    sink = Diags()
    compile_model(definition, sink, Options(out=tmp_path / "out"))
    error = sink.take_error("E0203")
    assert error.message == ("'actuators' must be one of 'motors', 'position', 'velocity', 'motor' or "
                             "'none', got 'positoin'; did you mean 'position'?")
    assert (error.span.line, error.span.col) == (8, 18)
