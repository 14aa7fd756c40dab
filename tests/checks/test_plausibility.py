"""effort_covers_gravity (Pinocchio) and self_collision (coal) on small arms written here: each
fails on the case it is for, with its exact protocol line, and passes on the unchanged arm."""

from __future__ import annotations

import math
from pathlib import Path

from tests.checks.helpers import definition, result, run, write
from tests.fixtures import ARM_URDF, arm

# The arm's lower link with its COM 0.3 m beyond the elbow, so that the elbow carries a load.
LOADED = ARM_URDF.replace('<inertial>\n      <mass value="0.5"/>',
                          '<inertial>\n      <origin xyz="0 0 0.3"/>\n      <mass value="0.5"/>')
GRAVITY = "      - effort_covers_gravity\n"


def _tested(tmp_path: Path, urdf: str, tests: str, extra: str = ""):
    basefile = arm(tmp_path / "new", urdf)
    write(tmp_path / "m.yml", definition(basefile, "arm", tests, extra=extra))
    return run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")


# -- effort_covers_gravity ---------------------------------------------------------------------


def test_an_effort_limit_below_the_gravity_torque_fails(tmp_path: Path) -> None:
    """The shoulder holds 1 kg at 0.2 m and 0.5 kg at 0.7 m: 9.81 · 0.55 · sin 1.5 = 5.382 N·m
    at its limit ±1.5 (the first sample, -1.5, is reported)."""
    expected = 9.81 * (1 * 0.2 + 0.5 * 0.7) * math.sin(1.5)
    assert f"{expected:.4g}" == "5.382"
    protocol = _tested(tmp_path, LOADED.replace('effort="10"', 'effort="5"'), GRAVITY)
    effort = result(protocol, "effort_covers_gravity")
    assert effort.status == "failed" and protocol.failed
    assert effort.reason == ("joint 'shoulder': gravity 5.382 N·m at shoulder = -1.5, q = 0, "
                             "effort limit 5 N·m (×1.08)")
    assert effort.figure is not None and math.isclose(effort.figure, expected / 5, rel_tol=1e-9)
    assert effort.unit == "of the effort limit"


def test_the_unchanged_arm_holds_itself(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, LOADED, GRAVITY)
    effort = result(protocol, "effort_covers_gravity")
    assert (effort.status, effort.reason) == (
        "passed", "2 joints hold themselves over their ranges in 1 configuration; the most loaded: joint "
                  "'shoulder': gravity 5.382 N·m at shoulder = -1.5, q = 0, effort limit 10 N·m")
    assert effort.details[1] == "joint 'elbow': gravity 1.468 N·m at elbow = -1.5, q = 0, effort limit 5 N·m"


def test_a_named_pose_is_a_configuration_of_the_rest(tmp_path: Path) -> None:
    """With its range ±1, the elbow's worst at q = 0 is 0.5 · 9.81 · 0.3 · sin 1 = 1.238 N·m; with
    the shoulder at 1.5 (pose 'reach') the forearm passes the horizontal: at the sample nearest
    to it, elbow = 0.125, 0.5 · 9.81 · 0.3 · sin 1.625 = 1.469 N·m > 1.4."""
    weak_elbow = LOADED.replace('lower="-2" upper="2" effort="5"', 'lower="-1" upper="1" effort="1.4"')
    protocol = _tested(tmp_path, weak_elbow, GRAVITY)
    assert result(protocol, "effort_covers_gravity").status == "passed"
    protocol = _tested(tmp_path, weak_elbow, GRAVITY,
                       extra="  poses:\n    reach:\n      shoulder: 1.5\n")
    effort = result(protocol, "effort_covers_gravity")
    assert (effort.status, effort.reason) == (
        "failed",
        "joint 'elbow': gravity 1.469 N·m at elbow = 0.125, pose 'reach', effort limit 1.4 N·m (×1.05)")


def test_joints_without_an_effort_limit_are_named(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, LOADED.replace(' effort="5"', ' effort="0"'), GRAVITY)
    effort = result(protocol, "effort_covers_gravity")
    assert effort.status == "passed" and effort.details[-1] == "no effort limit: 'elbow'"


# -- self_collision ----------------------------------------------------------------------------

FOLDING = """\
<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.8 0.8 0.1"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <origin xyz="0 0 0.1"/><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="100" velocity="2"/>
  </joint>
  <link name="upper">
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.4"/></geometry></collision>
  </link>
  <joint name="elbow" type="revolute">
    <origin xyz="0 0 0.4"/><parent link="upper"/><child link="lower"/><axis xyz="0 1 0"/>
    <limit lower="-2.8" upper="2.8" effort="100" velocity="2"/>
  </joint>
  <link name="lower">
    <inertial><origin xyz="0 0 0.3"/><mass value="0.5"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial>
    <collision name="forearm"><origin xyz="0 0 0.3"/>
      <geometry><box size="0.05 0.05 0.6"/></geometry></collision>
  </link>
</robot>
"""
AT_FOLDED = "links 'base' and 'lower' collide at pose 'folded' (collisions 'base_collision' and 'forearm')"
COLLISION = "      - self_collision\n"
FOLDED = "  poses:\n    folded:\n      elbow: 2.6\n"  # the forearm's end 1.4 cm below the base's top


def test_the_arm_apart_passes_self_collision(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, FOLDING, COLLISION, extra="  poses:\n    bent:\n      elbow: 1.0\n")
    collision = result(protocol, "self_collision")
    assert (collision.status, collision.figure, collision.reason) == (
        "passed", 0.0, "1 pair of collisions (by the kinematic rules) apart in 2 configurations")


def test_links_colliding_at_a_named_pose_fail(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, FOLDING, COLLISION, extra=FOLDED)
    collision = result(protocol, "self_collision")
    assert (collision.status, collision.figure, collision.reason) == (
        "failed", 1.0, AT_FOLDED)
    assert f"| `self_collision` | ❌ failed | 1 pairs |  | {AT_FOLDED} |" in protocol.markdown().splitlines()


def test_links_colliding_at_the_zero_pose_fail(tmp_path: Path) -> None:
    sunk = FOLDING.replace('<collision name="forearm"><origin xyz="0 0 0.3"/>',
                           '<collision name="forearm"><origin xyz="0 0 -0.25"/>')
    collision = result(_tested(tmp_path, sunk, COLLISION), "self_collision")
    assert (collision.status, collision.reason) == (
        "failed", "links 'base' and 'lower' collide at q = 0 (collisions 'base_collision' and 'forearm')")


def test_bitmasks_say_which_links_may_collide(tmp_path: Path) -> None:
    apart = FOLDED + "  collisions:\n    base:\n      bitmask: 1\n    lower:\n      bitmask: 2\n"
    collision = result(_tested(tmp_path, FOLDING, COLLISION, extra=apart), "self_collision")
    assert (collision.status, collision.reason) == ("passed", "no two links' collision shapes may collide")
    shared = FOLDED + "  collisions:\n    base:\n      bitmask: 3\n    lower:\n      bitmask: 2\n"
    collision = result(_tested(tmp_path, FOLDING, COLLISION, extra=shared), "self_collision")
    assert (collision.status, collision.reason) == ("failed", AT_FOLDED)


def test_mesh_collisions_are_tested_by_their_triangles(tmp_path: Path) -> None:
    """The base's collision is the tetrahedron of tests/fixtures scaled to 0.4 m and moved 0.1 m
    along x. With the elbow at 2 the forearm is inside the tetrahedron's bounding box and 2 cm
    above its slanted face: apart (coal decides, not the boxes); folded it reaches into it."""
    tetra = FOLDING.replace('<collision><origin xyz="0 0 0.05"/><geometry><box size="0.8 0.8 0.1"/>',
                            '<collision><origin xyz="0.1 0 0"/><geometry><mesh filename="meshes/tetra.stl" '
                            'scale="4 4 4"/>')
    reach = "  poses:\n    reach:\n      elbow: 2.0\n"
    collision = result(_tested(tmp_path, tetra, COLLISION, extra=reach), "self_collision")
    assert (collision.status, collision.reason) == (
        "passed", "1 pair of collisions (by the kinematic rules) apart in 2 configurations")
    collision = result(_tested(tmp_path, tetra, COLLISION, extra=FOLDED), "self_collision")
    assert (collision.status, collision.reason) == ("failed", AT_FOLDED)
