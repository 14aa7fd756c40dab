"""joint_limits and the budgets (max_mesh_faces, max_mesh_bytes, max_collisions_per_link): each
fails on the change it is for, with its exact protocol line, and passes on the unchanged model."""

from __future__ import annotations

from pathlib import Path

from mpc.core.diagnostics import Sink
from tests.checks.helpers import definition, result, run, write
from tests.fixtures import ARM_URDF, arm

ARM = ARM_URDF.replace('lower="-1.5" upper="1.5"', 'lower="-2.5" upper="2.5"')


def _tested(tmp_path: Path, urdf: str, tests: str, release: str | None = None, extra: str = ""):
    """The protocol of `urdf` (in `new/`) with `tests`, compared with `release` (in `release/`)."""
    compare = ""
    if release is not None:
        arm(tmp_path / "release", release)
        compare = "      path: release/arm.urdf\n"
    basefile = arm(tmp_path / "new", urdf)
    write(tmp_path / "m.yml", definition(basefile, "arm", tests, compare=compare, extra=extra))
    return run(tmp_path / "m.yml", tmp_path / "out", tmp_path / "work")


# -- joint_limits ------------------------------------------------------------------------------


def test_a_narrowed_limit_fails_joint_limits(tmp_path: Path) -> None:
    narrowed = ARM.replace('lower="-2.5" upper="2.5"', 'lower="-1.0" upper="1.0"')
    protocol = _tested(tmp_path, narrowed, "      - joint_limits\n", release=ARM)
    limits = result(protocol, "joint_limits")
    assert limits.status == "failed" and protocol.failed
    assert limits.reason == ("joint 'shoulder': lower -2.5 → -1 (Δ +1.5 rad), upper 2.5 → 1 (Δ -1.5 rad) "
                             "(the release → now)")
    assert (limits.figure, limits.unit) == (1.0, "joints")
    assert "| `joint_limits` | ❌ failed | 1 joints | `rad` ≤ 0.03 rad, `distance` ≤ 0.003 m, `default` ≤ " \
           "0.01 rad/s or m/s, `default` ≤ 0.01 N·m or N (absolute) | joint 'shoulder': lower -2.5 → -1" \
           in protocol.markdown()


def test_the_unchanged_model_passes_joint_limits(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, ARM, "      - joint_limits\n", release=ARM)
    limits = result(protocol, "joint_limits")
    assert (limits.status, limits.reason) == ("passed", "the limits of 2 movable joints agree")
    assert protocol.changes == ()
    assert "**0 changes** beyond the tolerances (`mpc diff`).\n" in protocol.markdown()


def test_the_protocol_starts_with_the_diff_against_the_release(tmp_path: Path) -> None:
    narrowed = ARM.replace('lower="-2.5" upper="2.5"', 'lower="-1.0" upper="1.0"')
    markdown = _tested(tmp_path, narrowed, "      - joint_limits\n", release=ARM).markdown()
    head = markdown.split("| test |")[0]
    assert head.endswith("**1 change** beyond the tolerances (`mpc diff`):\n\n"
                         "- joint `shoulder`: limit lower -2.5 → -1, upper 2.5 → 1\n\n"), head


def test_velocity_and_effort_are_compared_with_their_tolerances(tmp_path: Path) -> None:
    slower = ARM.replace('effort="5" velocity="3"', 'effort="4.5" velocity="2.95"')
    protocol = _tested(tmp_path, slower, "      - joint_limits\n", release=ARM)
    assert result(protocol, "joint_limits").reason == (
        "joint 'elbow': velocity 3 → 2.95 (Δ -0.05 rad/s), effort 5 → 4.5 (Δ -0.5 N·m) (the release → now)")
    # bounds of its own: the velocity change is within 0.1, the effort change within 1
    protocol = _tested(tmp_path, slower, "      - joint_limits: {velocity: 0.1, effort: 1}\n", release=ARM)
    limits = result(protocol, "joint_limits")
    assert limits.status == "passed"
    assert [str(t) for t in limits.tolerances] == ["`rad` ≤ 0.03 rad", "`distance` ≤ 0.003 m",
                                                   "`velocity` ≤ 0.1 rad/s or m/s", "`effort` ≤ 1 N·m or N"]


def test_a_limit_that_disappears_fails(tmp_path: Path) -> None:
    continuous = ARM.replace('name="elbow" type="revolute"', 'name="elbow" type="continuous"')
    protocol = _tested(tmp_path, continuous, "      - joint_limits\n", release=ARM)
    assert result(protocol, "joint_limits").reason == \
        "joint 'elbow': lower -2 → none, upper 2 → none (the release → now)"


def test_without_a_compare_model_joint_limits_is_skipped(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, ARM, "      - joint_limits\n")
    limits = result(protocol, "joint_limits")
    assert (limits.status, limits.reason) == ("skipped", "no compare_model in the definition")


def _two_arms(left: tuple[float, float], right: tuple[float, float], right_effort: float = 10) -> str:
    """A torso with two one-joint arms: arm_left_joint and arm_right_joint."""
    def side(name: str, y: float, limits: tuple[float, float], effort: float) -> str:
        return (f'<joint name="arm_{name}_joint" type="revolute"><origin xyz="0 {y} 0.3"/>'
                f'<parent link="torso"/><child link="arm_{name}"/><axis xyz="1 0 0"/>'
                f'<limit lower="{limits[0]}" upper="{limits[1]}" effort="{effort}" velocity="2"/></joint>'
                f'<link name="arm_{name}"><inertial><origin xyz="0 0 -0.2"/><mass value="1"/>'
                '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial></link>')
    return ('<?xml version="1.0"?><robot name="arm"><link name="torso"><inertial><mass value="5"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
            '<visual><geometry><mesh filename="meshes/tetra.stl"/></geometry></visual></link>'
            + side("left", 0.2, left, 10) + side("right", -0.2, right, right_effort) + "</robot>")


def test_mirrored_joints_whose_limits_differ_fail(tmp_path: Path) -> None:
    tests = "      - joint_limits: {mirrored: [left, right]}\n"
    protocol = _tested(tmp_path, _two_arms((-1, 2), (-1.5, 2)), tests)
    limits = result(protocol, "joint_limits")
    assert limits.status == "failed"
    assert limits.reason == ("joints 'arm_left_joint' and 'arm_right_joint': lower -1 → -1.5 (Δ -0.5 rad) "
                             "('arm_left_joint' → 'arm_right_joint')")
    protocol = _tested(tmp_path, _two_arms((-1, 2), (-1, 2), right_effort=8), tests)
    assert result(protocol, "joint_limits").reason == \
        ("joints 'arm_left_joint' and 'arm_right_joint': effort 10 → 8 (Δ -2 N·m) "
         "('arm_left_joint' → 'arm_right_joint')")


def test_mirrored_joints_with_the_same_or_the_negated_range_pass(tmp_path: Path) -> None:
    tests = "      - joint_limits: {mirrored: [left, right]}\n"
    for right in ((-1, 2), (-2, 1)):
        protocol = _tested(tmp_path, _two_arms((-1, 2), right), tests)
        limits = result(protocol, "joint_limits")
        assert (limits.status, limits.reason) == (
            "passed", "the limits of 2 movable joints (no compare_model: mirrored joints only), 1 mirrored "
                      "pair agree")


def test_mirrored_joints_that_differ_from_the_release_fail(tmp_path: Path) -> None:
    """Both arms changed the same way: they agree with each other, not with the release."""
    release = _two_arms((-1, 2), (-2, 1))
    protocol = _tested(tmp_path, _two_arms((-1, 1.5), (-1.5, 1)),
                       "      - joint_limits: {mirrored: [left, right]}\n", release=release)
    limits = result(protocol, "joint_limits")
    assert limits.status == "failed" and limits.figure == 2.0
    assert limits.details == (
        "joint 'arm_left_joint': upper 2 → 1.5 (Δ -0.5 rad) (the release → now)",
        "joint 'arm_right_joint': lower -2 → -1.5 (Δ +0.5 rad) (the release → now)")


def test_mirrored_names_that_match_no_joint_fail(tmp_path: Path) -> None:
    protocol = _tested(tmp_path, ARM, "      - joint_limits: {mirrored: [left, right]}\n")
    assert result(protocol, "joint_limits").reason == (
        "no joint has a mirror image: no name holds 'left' with a joint of the name with 'right' for it")


# -- budgets -----------------------------------------------------------------------------------


def test_max_mesh_faces(tmp_path: Path) -> None:
    """The arm's one mesh is a tetrahedron: 4 faces."""
    protocol = _tested(tmp_path, ARM, "      - max_mesh_faces: 4\n")
    faces = result(protocol, "max_mesh_faces")
    assert (faces.status, faces.figure, faces.reason) == (
        "passed", 4.0, "the largest, 'meshes/stl/tetra.stl': 4 faces ≤ 4")
    protocol = _tested(tmp_path, ARM, "      - max_mesh_faces: 3\n")
    faces = result(protocol, "max_mesh_faces")
    assert (faces.status, faces.reason) == ("failed", "'meshes/stl/tetra.stl': 4 faces > 3")
    line = "| `max_mesh_faces` | ❌ failed | 4 faces |  | 'meshes/stl/tetra.stl': 4 faces > 3 |"
    assert line in protocol.markdown().splitlines()


def test_max_mesh_faces_reads_other_formats(tmp_path: Path) -> None:
    """An OBJ (no header to read the count from) of two triangles."""
    write(tmp_path / "new" / "meshes" / "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    quad = ARM.replace("meshes/tetra.stl", "meshes/quad.obj")
    protocol = _tested(tmp_path, quad, "      - max_mesh_faces: 1\n")
    assert result(protocol, "max_mesh_faces").reason == "'meshes/obj/quad.obj': 2 faces > 1"


def test_max_mesh_bytes(tmp_path: Path) -> None:
    """A binary STL of 4 triangles: 84 + 4 · 50 = 284 bytes."""
    protocol = _tested(tmp_path, ARM, '      - max_mesh_bytes: "2 * 142"\n')  # an expression
    size = result(protocol, "max_mesh_bytes")
    assert (size.status, size.figure, size.reason) == ("passed", 284.0, "1 mesh file, 284 bytes ≤ 284")
    protocol = _tested(tmp_path, ARM, "      - max_mesh_bytes: 283\n")
    size = result(protocol, "max_mesh_bytes")
    assert (size.status, size.reason, size.details) == (
        "failed", "1 mesh file, 284 bytes > 283", ("'meshes/stl/tetra.stl': 284 bytes",))


def test_max_collisions_per_link(tmp_path: Path) -> None:
    box = ARM[ARM.index("<collision>"):ARM.index("</collision>") + len("</collision>")]
    three = ARM.replace(box, box * 3)
    protocol = _tested(tmp_path, ARM, "      - max_collisions_per_link: 2\n")
    assert result(protocol, "max_collisions_per_link").reason == "the largest, link 'upper': 1 collision ≤ 2"
    protocol = _tested(tmp_path, three, "      - max_collisions_per_link: 2\n")
    count = result(protocol, "max_collisions_per_link")
    assert (count.status, count.figure, count.reason) == ("failed", 3.0, "link 'upper': 3 collisions > 2")


def test_bad_budget_and_joint_limits_arguments(tmp_path: Path) -> None:
    from mpc.compiler.driver import Options, compile_model

    cases = {
        "max_mesh_faces": "test 'max_mesh_faces' needs an argument: the largest number of faces of a mesh",
        "max_mesh_bytes: -1": "test 'max_mesh_bytes': the limit is a whole number of bytes, at least 0, "
                              "got -1",
        "max_collisions_per_link: 1.5": "test 'max_collisions_per_link': the limit is a whole number of "
                                        "collision shapes, at least 0, got 1.5",
        "joint_limits: {effort: -1}": "test 'joint_limits': 'effort' must not be negative, got -1",
        "joint_limits: {mirrored: [left]}": "test 'joint_limits': 'mirrored' is the two parts of the names "
                                            "that tell mirrored joints apart, e.g. [left, right], "
                                            "got ['left']",
        "joint_limits: {position: 1, speed: 2}": "test 'joint_limits': unknown key 'speed' (it takes "
                                                 "'position', 'velocity', 'effort' and 'mirrored')",
        "effort_covers_gravity: 2": "test 'effort_covers_gravity' takes no argument",
    }
    basefile = arm(tmp_path / "new", ARM)
    for item, message in cases.items():
        tests = f"      - {item}\n"
        text = write(tmp_path / "m.yml", definition(basefile, "arm", tests)).read_text()
        line = text.splitlines().index(tests.rstrip("\n")) + 1
        sink = Sink()
        compile_model(tmp_path / "m.yml", sink, Options(out=tmp_path / "out"))
        found = [(d.code, d.message) for d in sink.diagnostics if d.severity.name == "ERROR"]
        assert found == [("E0703", message)], tests
        assert [(d.span.line, d.span.col) for d in sink.diagnostics if d.code == "E0703"] == [(line, 9)]


def test_the_editor_completes_the_new_tests() -> None:
    """The LSP offers what the registry implements (lsp/completion.py test_names)."""
    from mpc.lsp.completion import test_names

    assert {"joint_limits", "max_mesh_faces", "max_mesh_bytes", "max_collisions_per_link",
            "effort_covers_gravity", "self_collision"} <= set(test_names())
