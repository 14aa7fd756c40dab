"""The URDF writer against its recorded outputs (tests/golden.py): the bytes it writes for
every robot of example-robot-data, seeded mutations of them (odd names, extra attributes,
comments, fragments) and variants of their IR the reader never makes, with and without float
formats.

mpc's outputs are byte-stable: the digests were recorded by the writer of issue 19 (the one
that wrote the same bytes as its frozen predecessor), and `MPC_UPDATE_GOLDEN=1` records them
again. That what is written is *right* (Pinocchio reads the same model, check_urdf accepts
it) is for test_roundtrip.py and test_urdf_writer.py.
"""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Iterator

from mpc.backends import urdf_reader, urdf_writer
from mpc.backends.float_formats import URDF_KEYS, Formats
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from mpc.ir.geometry import Mesh
from mpc.ir.robot import Limit, Material, Mimic, Pose, Robot, SafetyController
from tests.backends.test_reader_golden import URDFS
from tests.backends.urdf_mutations import mutate
from tests.golden import check_digests, check_text, digest, stable

WHOLE = "double_pendulum_simple.urdf variant"  # kept whole as well
FORMATS = [None, {"default": "%.6f"}, {"xyz": "%.3f", "ixx": "%g", "value": "%e"}, {"rpy": "%+.2f"}]


def _uri(mesh: Mesh) -> str:
    return mesh.source.uri


def _variant(robot: Robot, rng: random.Random) -> Robot:
    """The robot with some values the reader never makes (as compiled definitions do)."""
    links = dict(robot.links)
    joints = dict(robot.joints)
    for name in rng.sample(sorted(joints), min(3, len(joints))):
        j = joints[name]
        joints[name] = dataclasses.replace(
            j, limit=Limit(lower=None, upper=1.5, effort=None, velocity=2.0),
            mimic=Mimic(joint=j.name, multiplier=None, offset=-0.0) if rng.random() < 0.5 else None,
            safety_controller=SafetyController(k_velocity=1e-20, soft_lower_limit=float("inf")),
            origin=Pose((1e16, -0.0, 1 / 3), (0.0, 0.0, 0.0), (rng.random() < 0.5, True)))
    for name in rng.sample(sorted(links), min(3, len(links))):
        link = links[name]
        visuals = tuple(dataclasses.replace(
            v, material="m&<\"'\n", inline_material=Material(name="m&<\"'\n", rgba=None, texture=""))
            for v in link.visuals)
        links[name] = dataclasses.replace(link, visuals=visuals, comments=(" a -- comment ",),
                                          extra_attrs=(("x", "a\tb\r\nc"),))
    materials = {**robot.materials, "t": Material(name="t", rgba=(0.5, 1.0, 0.0, 1.0), texture=None),
                 "u": Material(name="u", rgba=None, texture="u.png")}
    return dataclasses.replace(robot, links=links, joints=joints, materials=materials)


def _robots() -> Iterator[tuple[str, Robot]]:
    for path in URDFS:
        robot = urdf_reader.read(path, Sink())
        if robot is not None:
            yield path.name, robot
            yield f"{path.name} variant", _variant(robot, random.Random(path.name))
    documents = [(p, p.read_bytes()) for p in URDFS if p.stat().st_size < 40_000]
    for seed in range(400):
        rng = random.Random(seed)
        path, data = rng.choice(documents)
        robot = urdf_reader.read_text(mutate(data, seed), path.name, path.parent, Sink(), PackageResolver())
        if robot is not None:
            yield f"{path.name} seed {seed}", robot


ROBOTS = list(_robots())


def _written(robot: Robot, formats: dict[str, str] | None) -> str:
    try:
        return urdf_writer.to_string(robot, _uri, Formats(formats, URDF_KEYS) if formats else None)
    except ValueError as e:  # a format of a text that is no number
        return f"ValueError: {e}"


def test_every_robot_is_written_as_recorded() -> None:
    """One digest a robot: its texts in every float format of FORMATS."""
    found = {}
    for name, robot in ROBOTS:
        texts = [f"# formats {formats}\n{_written(robot, formats)}" for formats in FORMATS]
        found[name] = digest(stable("\n".join(texts)))
    assert len(ROBOTS) > 300
    check_digests("writer_urdfs", found)
    check_text("writer/double_pendulum_simple", stable(_written(dict(ROBOTS)[WHOLE], None)))
