"""Every MJCF robot that gymnasium-robotics and dm-control ship (read where pip installed them),
read by mpc and exported to URDF and MJCF: total mass, every body's pose at q = 0 and at 10
random configurations, and the joint ranges equal MuJoCo's compiled original to 1e-9
(Pinocchio for the URDF, MuJoCo for the MJCF). What the IR cannot hold is the exact W0440.

A robot is an XML file MuJoCo loads on its own (`MjModel.from_xml_path`) with at least one
body and one joint: include-only fragments (`<mujocoinclude>`, files that name what their
includer defines), schemas and pure scenes (no joint) are not robots.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import mujoco
import pytest

from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Severity
from tests.backends.mjcf_compare import assert_mjcf_matches, assert_urdf_matches
from tests.conftest import Diags

# robot → what its W0440 names ("" for none)
ROBOTS = {
    "gymnasium_robotics/envs/assets/adroit_hand/adroit_door.xml":
        "camera ×2, contact pair ×19, light ×1, plane ×1, sensor ×65, tendon ×44, texture ×9",
    "gymnasium_robotics/envs/assets/adroit_hand/adroit_hammer.xml":
        "camera ×2, contact exclusion ×1, contact pair ×19, light ×1, plane ×1, sensor ×66, "
        "tendon ×44, texture ×9",
    "gymnasium_robotics/envs/assets/adroit_hand/adroit_pen.xml":
        "camera ×7, contact pair ×19, light ×1, plane ×1, sensor ×65, tendon ×44, texture ×9",
    "gymnasium_robotics/envs/assets/adroit_hand/adroit_relocate.xml":
        "camera ×2, contact pair ×19, light ×1, plane ×1, sensor ×65, tendon ×44, texture ×9",
    "gymnasium_robotics/envs/assets/fetch/pick_and_place.xml":
        "camera ×4, contact exclusion ×3, light ×1, plane ×1, texture ×2",
    "gymnasium_robotics/envs/assets/fetch/push.xml":
        "camera ×4, contact exclusion ×3, light ×1, plane ×1, texture ×2",
    "gymnasium_robotics/envs/assets/fetch/reach.xml":
        "camera ×4, contact exclusion ×3, light ×1, plane ×1, texture ×2",
    "gymnasium_robotics/envs/assets/fetch/slide.xml":
        "camera ×4, contact exclusion ×3, light ×1, plane ×1, texture ×2",
    "gymnasium_robotics/envs/assets/hand/manipulate_block.xml":
        "contact pair ×19, light ×1, plane ×1, sensor ×29, tendon ×44, texture ×5",
    "gymnasium_robotics/envs/assets/hand/manipulate_block_touch_sensors.xml":
        "contact pair ×19, light ×1, plane ×1, sensor ×121, tendon ×44, texture ×5",
    "gymnasium_robotics/envs/assets/hand/manipulate_egg.xml":
        "contact pair ×19, ellipsoid ×3, light ×1, plane ×1, sensor ×29, tendon ×44, texture ×5",
    "gymnasium_robotics/envs/assets/hand/manipulate_egg_touch_sensors.xml":
        "contact pair ×19, ellipsoid ×3, light ×1, plane ×1, sensor ×121, tendon ×44, texture ×5",
    "gymnasium_robotics/envs/assets/hand/manipulate_pen.xml":
        "contact pair ×19, light ×1, plane ×1, sensor ×29, tendon ×44, texture ×3",
    "gymnasium_robotics/envs/assets/hand/manipulate_pen_touch_sensors.xml":
        "contact pair ×19, light ×1, plane ×1, sensor ×121, tendon ×44, texture ×3",
    "gymnasium_robotics/envs/assets/hand/reach.xml":
        "contact pair ×19, light ×1, plane ×1, sensor ×29, tendon ×44, texture ×3",
    "gymnasium_robotics/envs/assets/kitchen_franka/kitchen_assets/kitchen_env_model.xml":
        "camera ×2, light ×4, plane ×1, texture ×14",  # its 5 joint equalities: mimics
    "gymnasium_robotics/envs/assets/point/point.xml":
        "plane ×1, texture ×2",
    "gymnasium_robotics/envs/mujoco/assets/ant.xml":
        "camera ×1, custom numeric ×1, light ×1, texture ×3, worldbody geom ×1",
    "gymnasium_robotics/envs/mujoco/assets/half_cheetah.xml":
        "camera ×1, light ×1, plane ×1, texture ×3",
    "gymnasium_robotics/envs/mujoco/assets/hopper.xml":
        "camera ×1, light ×1, plane ×1, texture ×3",
    "gymnasium_robotics/envs/mujoco/assets/humanoid.xml":
        "camera ×2, light ×1, tendon ×2, texture ×3, worldbody geom ×1",
    "gymnasium_robotics/envs/mujoco/assets/humanoidstandup.xml":
        "camera ×2, light ×1, tendon ×2, texture ×3, worldbody geom ×1",
    "gymnasium_robotics/envs/mujoco/assets/inverted_double_pendulum.xml":
        "custom numeric ×1, plane ×1",
    "gymnasium_robotics/envs/mujoco/assets/inverted_pendulum.xml": "",
    "gymnasium_robotics/envs/mujoco/assets/point.xml":
        "light ×1, plane ×1, texture ×3",
    "gymnasium_robotics/envs/mujoco/assets/pusher.xml":
        "light ×1, plane ×1",
    "gymnasium_robotics/envs/mujoco/assets/reacher.xml":
        "plane ×1",
    "gymnasium_robotics/envs/mujoco/assets/swimmer.xml":
        "camera ×1, light ×1, plane ×1, texture ×3",
    "gymnasium_robotics/envs/mujoco/assets/walker2d.xml":
        "camera ×1, light ×1, plane ×1, texture ×3",
    "gymnasium_robotics/envs/multiagent_mujoco/assets/coupled_half_cheetah.xml":
        "camera ×2, light ×1, plane ×1, tendon ×1, texture ×3",
    "dm_control/locomotion/soccer/assets/boxhead/boxhead.xml":
        "camera ×3, sensor ×3",
    "dm_control/locomotion/walkers/assets/build_fruitfly/assets/drosophila_fused.xml": "",
    "dm_control/locomotion/walkers/assets/dog_v2/dog.xml":
        "actuator not on a hinge or slide ×8, camera ×2, contact exclusion ×30, ellipsoid ×46, "
        "light ×1, sensor ×13, skin ×1, tendon ×8, texture ×2, worldbody geom ×1",
    "dm_control/locomotion/walkers/assets/fruitfly_v2/floor.xml":
        "actuator not on a hinge or slide ×16, camera ×9, contact exclusion ×26, ellipsoid ×18, "
        "light ×3, sensor ×15, tendon ×8, texture ×2, worldbody geom ×1",
    "dm_control/locomotion/walkers/assets/fruitfly_v2/fruitfly.xml":
        "actuator not on a hinge or slide ×16, camera ×9, contact exclusion ×26, ellipsoid ×18, "
        "light ×3, sensor ×15, tendon ×8",
    "dm_control/locomotion/walkers/assets/humanoid_CMU_V2019.xml":
        "camera ×7, contact exclusion ×5, ellipsoid ×2, light ×1, sensor ×15",
    "dm_control/locomotion/walkers/assets/humanoid_CMU_V2020.xml":
        "camera ×5, contact exclusion ×5, ellipsoid ×2, light ×1, sensor ×15",
    "dm_control/locomotion/walkers/assets/jumping_ball/jumping_ball_with_head.xml":
        "camera ×2, sensor ×3, texture ×1",
    "dm_control/locomotion/walkers/assets/rodent.xml":
        "actuator not on a hinge or slide ×8, camera ×5, contact exclusion ×26, ellipsoid ×22, "
        "light ×1, sensor ×8, skin ×1, tendon ×8",
    "dm_control/mjcf/test_assets/robot_arm.xml":
        "camera ×1, contact exclusion ×4, sensor ×9",
    "dm_control/mujoco/testing/assets/arm.xml":
        "contact exclusion ×4, worldbody geom ×1",
    "dm_control/mujoco/testing/assets/cartpole.xml":
        "camera ×3, custom numeric ×2, plane ×1, sensor ×2",
    "dm_control/mujoco/testing/assets/cartpole_no_names.xml":
        "camera ×3, custom numeric ×1, plane ×1, sensor ×2",
    "dm_control/mujoco/testing/assets/humanoid.xml":
        "camera ×2, light ×1, tendon ×2, texture ×3, worldbody geom ×1",
    "dm_control/mujoco/testing/assets/model_with_ball_joints.xml":
        "ball joint ×2",
    "dm_control/mujoco/testing/assets/model_with_third_order_actuators.xml": "",
    "dm_control/suite/acrobot.xml":
        "camera ×2, light ×1, plane ×1, texture ×2",
    "dm_control/suite/ball_in_cup.xml":
        "camera ×2, light ×1, plane ×1, tendon ×1, texture ×2",
    "dm_control/suite/cartpole.xml":
        "camera ×2, light ×1, plane ×1, texture ×2",
    "dm_control/suite/cheetah.xml":
        "camera ×2, light ×1, plane ×1, sensor ×1, texture ×2",
    "dm_control/suite/dog.xml":
        "actuator not on a hinge or slide ×8, camera ×4, contact exclusion ×30, ellipsoid ×46, "
        "light ×1, plane ×5, sensor ×13, skin ×1, tendon ×8, texture ×4",
    "dm_control/suite/finger.xml":
        "camera ×2, light ×1, plane ×1, sensor ×12, texture ×2",
    "dm_control/suite/fish.xml":
        "actuator not on a hinge or slide ×1, camera ×5, ellipsoid ×7, light ×1, sensor ×2, "
        "tendon ×2, texture ×2, worldbody geom ×2",
    "dm_control/suite/hopper.xml":
        "camera ×2, light ×1, plane ×1, sensor ×3, texture ×2",
    "dm_control/suite/humanoid.xml":
        "camera ×3, light ×1, sensor ×34, texture ×2, worldbody geom ×1",
    "dm_control/suite/humanoid_CMU.xml":
        "camera ×3, contact exclusion ×5, ellipsoid ×2, light ×1, sensor ×8, texture ×2, "
        "worldbody geom ×1",
    "dm_control/suite/manipulator.xml":
        "actuator not on a hinge or slide ×1, camera ×2, "
        "equality other than a connect or weld of bodies ×1, light ×1, plane ×4, sensor ×5, "
        "tendon ×2, texture ×3",
    "dm_control/suite/pendulum.xml":
        "camera ×2, light ×1, plane ×1, texture ×2",
    "dm_control/suite/point_mass.xml":
        "actuator not on a hinge or slide ×2, camera ×2, light ×1, plane ×5, tendon ×2, texture ×2",
    "dm_control/suite/quadruped.xml":
        "actuator not on a hinge or slide ×8, camera ×4, ellipsoid ×1, "
        "equality other than a connect or weld of bodies ×4, height field ×1, light ×2, plane ×5, "
        "sensor ×32, tendon ×12, texture ×3",
    "dm_control/suite/reacher.xml":
        "camera ×2, light ×1, plane ×5, texture ×2",
    "dm_control/suite/stacker.xml":
        "actuator not on a hinge or slide ×1, camera ×2, "
        "equality other than a connect or weld of bodies ×1, light ×1, plane ×4, sensor ×5, "
        "tendon ×2, texture ×3",
    "dm_control/suite/swimmer.xml":
        "camera ×3, ellipsoid ×1, light ×2, plane ×1, sensor ×6, texture ×2",
    "dm_control/suite/walker.xml":
        "camera ×2, light ×1, plane ×1, sensor ×1, texture ×2",
    "dm_control/third_party/ant/ant.xml":
        "camera ×4, contact exclusion ×4, sensor ×20",
    "dm_control/third_party/kinova/jaco_arm.xml":
        "contact exclusion ×1",
    "dm_control/third_party/kinova/jaco_hand.xml":
        "contact exclusion ×3",
}


def _package_root(package: str) -> Path:
    spec = importlib.util.find_spec(package)
    assert spec is not None and spec.submodule_search_locations
    return Path(next(iter(spec.submodule_search_locations)))


def _robots() -> list[str]:
    """The robots of both packages, found the way the docstring says (so a new robot in a new
    release fails `test_the_list_is_complete` until it is listed)."""
    found = []
    for package in ("gymnasium_robotics", "dm_control"):
        root = _package_root(package)
        for xml in sorted(root.rglob("*.xml")):
            try:
                model = mujoco.MjModel.from_xml_path(str(xml))
            except ValueError:
                continue
            if model.nbody >= 2 and model.njnt >= 1:
                found.append(f"{package}/{xml.relative_to(root)}")
    return found


def test_the_list_is_complete(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo's warnings go to MUJOCO_LOG.TXT in the working folder
    assert _robots() == list(ROBOTS)


@pytest.mark.long
@pytest.mark.parametrize("robot", list(ROBOTS))
def test_pypi_robot_is_physically_equal(robot: str, tmp_path: Path, diags: Diags,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo's warnings go to MUJOCO_LOG.TXT in the working folder
    package, rest = robot.split("/", 1)
    xml = _package_root(package) / rest
    unheld = ROBOTS[robot]
    exports = "    - type: urdf\n    - type: mjcf\n"
    (tmp_path / "robot.yml").write_text(f"""model:
  robotname: r
  modelname: r-model
  input_models:
    base:
      basefile: "{xml}"
  assemble:
    model: base
  export_config:
{exports}""")
    options = Options(out=tmp_path / "out")
    options.resolver.add_project(_package_root(package))
    compile_model(tmp_path / "robot.yml", diags, options)
    if unheld:
        assert diags.take("W0440", Severity.WARNING).message == (
            f"'{xml}' holds what mpc's robot model cannot: {unheld}; left out")
    while any(d.code in ("W0441", "W0500", "W0505") for d in diags.diagnostics):
        diags.take(next(d.code for d in diags.diagnostics if d.code in ("W0441", "W0500", "W0505")),
                   Severity.WARNING)
    assert not diags.has_errors(), diags.summary()
    original = mujoco.MjModel.from_xml_path(str(xml))
    assert_urdf_matches(original, tmp_path / "out" / "urdf" / "r.urdf")
    assert_mjcf_matches(original, tmp_path / "out" / "mjcf" / "r.xml")
