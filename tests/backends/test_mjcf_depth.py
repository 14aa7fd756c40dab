"""MuJoCo's limit on nested bodies: the deepest chain mpc writes loads in MuJoCo, one link
more is E0695 (and MuJoCo itself refuses it), and the export writes nothing then."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from mpc.backends import mjcf
from mpc.core.span import Span
from mpc.ir.geometry import Box
from mpc.ir.program import MjcfExport
from mpc.ir.robot import Collision, Inertia, Inertial, Joint, Limit, Link, Pose, Robot
from tests.conftest import Diags

SPAN = Span("model.yml", 7, 9)


def _chain(n: int, root: str = "l0", floating_top: bool = False) -> Robot:
    """`n` links, each hanging from the previous one by a revolute joint (the first by a
    floating one when `floating_top`)."""
    inertial = Inertial(mass=1.0, inertia=Inertia(ixx=0.01, ixy=0.0, ixz=0.0, iyy=0.01, iyz=0.0, izz=0.01))
    names = [root, *(f"l{i}" for i in range(1, n))]
    box = (Collision(geometry=Box(size=(0.1, 0.1, 0.1))),)
    links = {name: Link(name=name, inertial=inertial, collisions=box) for name in names}
    joints = {f"j{i}": Joint(name=f"j{i}", type="floating" if floating_top and i == 1 else "revolute",
                             parent=names[i - 1], child=names[i], origin=Pose((0.0, 0.0, 0.1)),
                             axis=(0.0, 1.0, 0.0),
                             limit=Limit(lower=-1.0, upper=1.0, effort=1.0, velocity=1.0))
              for i in range(1, n)}
    return Robot(name="chain", root=root, links=links, joints=joints)


def test_the_deepest_chain_loads_and_one_link_more_is_refused_by_mujoco() -> None:
    deepest = mjcf.to_string(_chain(mjcf.MAX_BODY_DEPTH), str)
    assert mujoco.MjModel.from_xml_string(deepest).nbody == mjcf.MAX_BODY_DEPTH + 1  # and the world
    with pytest.raises(ValueError, match="nesting is too deep"):
        mujoco.MjModel.from_xml_string(mjcf.to_string(_chain(mjcf.MAX_BODY_DEPTH + 1), str))


@pytest.mark.parametrize(("robot", "depth"), [
    (_chain(10), 10),
    (_chain(10, root="world"), 9),  # the world link is MuJoCo's world body
    (_chain(10, floating_top=True), 9),  # l1 is hoisted to the world
])
def test_body_depth_counts_the_bodies_mjcf_nests(robot: Robot, depth: int) -> None:
    assert mjcf.body_depth(robot) == (depth, "l9")


def test_a_chain_too_deep_for_mujoco_is_e0695_and_nothing_is_written(tmp_path: Path, diags: Diags) -> None:
    mjcf.emit(_chain(mjcf.MAX_BODY_DEPTH + 4), MjcfExport(mesh_format="stl", span=SPAN), tmp_path, diags)
    d = diags.take_error("E0695")
    assert (d.span, d.message) == (SPAN, (
        "the MJCF cannot hold this robot: its bodies would nest 500 deep (down to link 'l499'), "
        "and MuJoCo's XML reader refuses elements nested deeper than 496 bodies; no MJCF is written"))
    assert not any(tmp_path.iterdir())
