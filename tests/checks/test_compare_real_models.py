"""The compare tests on real robots: a model against itself passes everything; one change of
twice (or 1.5 times) a tolerance fails exactly the tests that measure it."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.checks.protocol import Tolerance
from tests.checks.helpers import (
    EVERY_TEST,
    compile_ok,
    definition,
    edited_urdf,
    failing,
    floats,
    fmt,
    joint_el,
    link_el,
    result,
    run,
    statuses,
    write,
)
from tests.conftest import ERD

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"
G1 = ERD / "g1_description/urdf/g1_29dof_rev_1_0.urdf"
TOL = {"mass": 0.01, "distance": 0.003, "rad": 0.03, "default": 0.01}


def reference(folder: Path, source: Path = TALOS, name: str = "talos") -> Path:
    """The released model: `source` compiled into folder/ref."""
    write(folder / "ref.yml", definition(source, name, "      - compare_amount_joints\n"))
    compile_ok(folder / "ref.yml", folder / "ref")
    return folder / "ref"


@pytest.fixture(scope="module")
def talos(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """TALOS's release, compiled once for the tests of this module (none of them changes it)."""
    return reference(tmp_path_factory.mktemp("talos"))


def against_ref(tmp_path: Path, basefile: Path, ref: Path, tests: str = EVERY_TEST, extra: str = "",
                name: str = "talos"):
    text = definition(basefile, name, tests, compare=f"      path: {ref}\n", extra=extra)
    write(tmp_path / "new.yml", text)
    return run(tmp_path / "new.yml", tmp_path / "new", tmp_path / "work")


def test_talos_against_itself_passes_every_test(tmp_path: Path, talos: Path) -> None:
    protocol = against_ref(tmp_path, TALOS, talos, EVERY_TEST + "          - move_hyrodyn_model: 0.4\n"
                           "          - compare_torques\n          - compare_com\n")
    assert set(statuses(protocol).values()) == {"passed"}, protocol.markdown()
    assert not protocol.failed
    assert result(protocol, "load_in_pybullet").figure == 60  # every link made by PyBullet
    moved = result(protocol, "compare_torques 2")
    assert moved.figure == 0.0 and "at 0.4 for every joint" in moved.reason


def test_g1_against_itself_passes_every_test_symmetry_included(tmp_path: Path) -> None:
    reference(tmp_path, G1, "g1")
    pair = "[left_ankle_roll_link, right_ankle_roll_link]"
    tests = (EVERY_TEST + f"          - symmetry_check: {pair}\n          - symmetry_check_torques: {pair}\n"
             f"      - symmetry_check_masses: {pair}\n      - total_mass: 33.3411\n")
    protocol = against_ref(tmp_path, G1, tmp_path / "ref", tests, name="g1")
    assert set(statuses(protocol).values()) == {"passed"}, protocol.markdown()
    assert result(protocol, "symmetry_check").figure < 1e-9
    assert result(protocol, "symmetry_check_masses").figure == 0.0


def test_a_link_mass_changed_by_twice_the_tolerance(tmp_path: Path, talos: Path) -> None:
    """The root link's mass: it loads no joint of a fixed-base model, so torques and COM
    (0.02 kg on 93 kg) stay within their tolerances, and only the mass tests fail."""

    def heavier(root):
        mass = link_el(root, "base_link").find("inertial/mass")
        mass.set("value", repr(float(mass.get("value")) + 2 * TOL["mass"]))

    protocol = against_ref(tmp_path, edited_urdf(TALOS, tmp_path / "in/talos.urdf", heavier), talos)
    assert failing(protocol) == {"compare_link_masses", "compare_masses"}, protocol.markdown()
    links = result(protocol, "compare_link_masses")
    assert links.figure == pytest.approx(0.02, abs=1e-9)
    assert links.tolerances == (Tolerance("mass", 0.01, "kg"),)
    assert "'base_link' by +0.02 kg" in links.reason
    assert result(protocol, "compare_masses").figure == pytest.approx(0.02, abs=1e-9)
    assert protocol.failed


def test_a_joint_origin_moved_by_twice_the_distance(tmp_path: Path, talos: Path) -> None:

    def moved(root):
        origin = joint_el(root, "arm_left_4_joint").find("origin")
        xyz = floats(origin.get("xyz"))
        xyz[0] += 2 * TOL["distance"]
        origin.set("xyz", fmt(xyz))

    protocol = against_ref(tmp_path, edited_urdf(TALOS, tmp_path / "in/talos.urdf", moved), talos)
    failed = failing(protocol)
    # The arm beyond the joint moved: the torques that hold it changed with it (by about
    # m·g·6 mm), the masses, the COM (0.2 mm) and the tree did not.
    assert failed == {"compare_link_transformations", "compare_link_positions", "compare_torques"}, \
        protocol.markdown()
    for name in ("compare_link_transformations", "compare_link_positions"):
        r = result(protocol, name)
        assert r.figure == pytest.approx(0.006, abs=1e-9)
        assert r.tolerances == (Tolerance("distance", 0.003, "m"), Tolerance("rad", 0.03, "rad"))
    assert "arm_left_4_link" in "\n".join(result(protocol, "compare_link_transformations").details)


def test_a_joint_type_changed(tmp_path: Path, talos: Path) -> None:
    extra = "  joints:\n    arm_left_4_joint:\n      type: continuous\n"
    protocol = against_ref(tmp_path, TALOS, talos, extra=extra)
    assert failing(protocol) == {"topological_self_consistency"}, protocol.markdown()
    assert result(protocol, "topological_self_consistency").reason == \
        "joint 'arm_left_4_joint' changed its type from revolute to continuous"
    assert statuses(protocol)["process_double_check"] == "passed"  # the definition asked for it


@pytest.mark.parametrize(("factor", "fails"), [(1.5, True), (0.5, False)])
def test_the_com_moved_by_a_multiple_of_the_distance(tmp_path: Path, talos: Path, factor: float,
                                                      fails: bool) -> None:
    """Phobos's compare_com measured against 1 m; a COM 4.5 mm off must fail at 3 mm."""
    total, base = 93.33572, 15.36284

    def shifted(root):
        origin = link_el(root, "base_link").find("inertial/origin")
        xyz = floats(origin.get("xyz"))
        xyz[1] += factor * TOL["distance"] * total / base  # moves the whole COM by factor·distance
        origin.set("xyz", fmt(xyz))

    protocol = against_ref(tmp_path, edited_urdf(TALOS, tmp_path / "in/talos.urdf", shifted), talos)
    assert failing(protocol) == ({"compare_com"} if fails else set()), protocol.markdown()
    com = result(protocol, "compare_com")
    assert com.figure == pytest.approx(factor * TOL["distance"], rel=1e-4)
    assert com.tolerances == (Tolerance("distance", 0.003, "m"),)


def test_without_compare_model_the_compare_tests_are_skipped_not_passed(tmp_path: Path) -> None:
    write(tmp_path / "m.yml", definition(TALOS, "talos", EVERY_TEST + "      - total_mass\n"))
    protocol = run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")
    s = statuses(protocol)
    for name in ("compare_link_masses", "compare_link_transformations", "compare_amount_joints",
                 "compare_masses", "compare_com", "compare_torques", "compare_link_positions",
                 "file_consistency", "total_mass"):
        assert s[name] == "skipped", name
    assert result(protocol, "compare_masses").reason == "no compare_model in the definition"
    assert s["load_in_pybullet"] == s["load_in_hyrodyn"] == s["topological_self_consistency"] == "passed"
    assert not protocol.failed
    assert protocol.counts()["skipped"] == 9


def test_a_removed_link_is_a_breaking_change(tmp_path: Path, talos: Path) -> None:
    extra = "  joints:\n    head_2_joint:\n      remove: true\n"
    protocol = against_ref(tmp_path, TALOS, talos, "      - process_double_check\n", extra=extra)
    topo = result(protocol, "topological_self_consistency")
    assert topo.status == "failed"
    assert "joint 'head_2_joint' was removed or renamed" in topo.details
    assert "link 'head_2_link' was removed or renamed" in topo.details
    assert statuses(protocol)["process_double_check"] == "passed"  # it was asked for
