"""Every class of bad input gets a diagnostic with file, line and column; none raises.

Each test asserts the code, the exact message and the location.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import Diags, compile_file, definition, write
from tests.fixtures import ARM_URDF, arm


def _compile(tmp_path: Path, diags: Diags, spec_text: str) -> Path:
    spec = write(tmp_path / "model.yml", spec_text)
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert not (tmp_path / "out").exists()
    return spec


def _where(d) -> tuple[int, int]:
    return d.span.line, d.span.col


# -- the definition file --------------------------------------------------------------------

def test_missing_definition_file(tmp_path: Path, diags: Diags) -> None:
    assert compile_file(tmp_path / "nope.yml", tmp_path / "out", diags).out is None
    d = diags.take_error("E0601")
    assert d.message == f"file '{tmp_path}/nope.yml' does not exist"
    assert d.span.file == f"{tmp_path}/nope.yml"


def test_malformed_yaml(tmp_path: Path, diags: Diags) -> None:
    _compile(tmp_path, diags, "model:\n  robotname: [arm\n  modelname: x\n")
    d = diags.take_error("E0102")
    assert d.message == "malformed YAML: expected ',' or ']', but got ':'"
    assert _where(d) == (3, 12)


def test_empty_file(tmp_path: Path, diags: Diags) -> None:
    _compile(tmp_path, diags, "# nothing here\n")
    assert diags.take_error("E0104").message.endswith("model.yml' is empty")


def test_duplicate_key(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    text = definition("arm.urdf").replace("  modelname:", "  robotname: again\n  modelname:")
    _compile(tmp_path, diags, text)
    d = diags.take_error("E0103")
    assert d.message == "duplicate key 'robotname'"
    assert _where(d) == (3, 3)
    assert d.notes[0][0].line == 2


def test_unknown_key_with_did_you_mean(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    _compile(tmp_path, diags, definition("arm.urdf").replace("robotname:", "robtname:"))
    d = diags.take_error("E0201")
    assert d.message == "unknown key 'robtname' in model; did you mean 'robotname'?"
    assert _where(d) == (2, 3)
    missing = diags.take_error("E0203")  # and so robotname is missing
    assert missing.message == "model has no 'robotname', which is required"
    assert _where(missing) == (1, 1)


def test_key_of_a_later_version(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    _compile(tmp_path, diags, definition("arm.urdf") + "  swing_my_robot: true\n"
             "  test: {tests: [compare_link_masses]}\n")
    d = diags.take_error("E0202")  # `test` and `deployment` are lowered
    assert (d.message, _where(d)) == ("'swing_my_robot' is not supported yet", (12, 3))


def test_export_of_a_later_version(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    _compile(tmp_path, diags, definition("arm.urdf") + "    - {type: submodel, name: s, remove_links: [x]}\n")
    d = diags.take_error("E0202")
    assert (d.message, _where(d)) == ("submodel option 'remove_links' is not supported yet", (12, 33))


def test_wrong_type(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    _compile(tmp_path, diags, definition("arm.urdf").replace("robotname: robot", "robotname: [1]"))
    d = diags.take_error("E0203")
    assert d.message == "'robotname' must be a string, got a list"
    assert _where(d) == (2, 14)


def test_unknown_export_type_and_mesh_format(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    text = definition("arm.urdf", "stll") + "    - type: urdff\n"
    _compile(tmp_path, diags, text)
    fmt = diags.take_error("E0203")  # reported in the order of the document
    assert fmt.message == ("'mesh_format' must be one of 'stl', 'obj', 'dae', 'bobj', 'mars_obj' or "
                           "'input_type', got 'stll'; did you mean 'stl'?")
    assert _where(fmt) == (11, 20)
    typo = diags.take_error("E0203")
    assert (typo.message, _where(typo)) == ("unknown export type 'urdff'; did you mean 'urdf'?", (12, 13))


def test_assemble_model_that_is_no_input(tmp_path: Path, diags: Diags) -> None:
    arm(tmp_path)
    _compile(tmp_path, diags, definition("arm.urdf").replace("model: base", "model: bsae"))
    d = diags.take_error("E0301")
    assert d.message == ("model 'bsae' in assemble is not one of the input models (base); "
                         "did you mean 'base'?")
    assert _where(d) == (8, 12)


def test_missing_basefile(tmp_path: Path, diags: Diags) -> None:
    _compile(tmp_path, diags, definition("urdf/arm.urdf"))
    d = diags.take_error("E0601")
    assert d.message == f"basefile '{tmp_path}/urdf/arm.urdf' of input model 'base' does not exist"
    assert _where(d) == (6, 17)


# -- the URDF -------------------------------------------------------------------------------

def _urdf(tmp_path: Path, diags: Diags, urdf: str) -> Path:
    source = arm(tmp_path, urdf)
    _compile(tmp_path, diags, definition("arm.urdf"))
    return source


def test_malformed_xml(tmp_path: Path, diags: Diags) -> None:
    source = _urdf(tmp_path, diags, ARM_URDF.replace('<child link="upper"/>', '<child link="upper">'))
    d = diags.take_error("E0401")
    assert d.message == (f"malformed XML in '{source}': Opening and ending tag mismatch: "
                         "child line 16 and joint")
    assert (d.span.file, _where(d)) == (str(source), (19, 11))


def test_not_a_robot(tmp_path: Path, diags: Diags) -> None:
    source = _urdf(tmp_path, diags, '<?xml version="1.0"?>\n<sdf version="1.9"/>\n')
    d = diags.take_error("E0402")
    assert d.message == f"'{source}' is not a URDF: its root element is <sdf>, not <robot>"
    assert _where(d) == (2, 1)


def test_two_roots(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace('<parent link="upper"/>', '<parent link="lower"/>')
          .replace('<child link="lower"/>', '<child link="upper2"/>')
          .replace('<link name="lower">', '<link name="upper2"/>\n  <link name="lower">'))
    d = diags.take_error("E0414")
    assert d.message == "robot 'arm' has 2 root links (base, lower); a URDF must be one tree"
    assert _where(d) == (2, 1)
    assert [n[0].line for n in d.notes] == [3, 38]


def test_cycle(tmp_path: Path, diags: Diags) -> None:
    cyclic = ARM_URDF.replace("</robot>", """\
  <joint name="back" type="fixed">
    <parent link="lower"/>
    <child link="base"/>
  </joint>
</robot>
""")
    _urdf(tmp_path, diags, cyclic)
    d = diags.take_error("E0413")
    assert d.message == "robot 'arm' has no root link: its joints form a cycle"


def test_link_with_two_parents(tmp_path: Path, diags: Diags) -> None:
    twice = ARM_URDF.replace("</robot>", """\
  <joint name="again" type="fixed">
    <parent link="base"/>
    <child link="lower"/>
  </joint>
</robot>
""")
    _urdf(tmp_path, diags, twice)
    d = diags.take_error("E0412")
    assert d.message == ("link 'lower' is the child of two joints, 'elbow' and 'again'; "
                         "a URDF must be a tree")
    assert _where(d) == (43, 3)
    assert d.notes[0][0].line == 30


def test_joint_to_unknown_link(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace('<child link="lower"/>', '<child link="lowr"/>'))
    d = diags.take_error("E0411")
    assert d.message == "joint 'elbow' refers to unknown child link 'lowr'; did you mean 'lower'?"
    assert _where(d) == (30, 3)


def test_duplicate_link(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace('<link name="lower">', '<link name="upper">'))
    d = diags.take_error("E0410")
    assert d.message == "duplicate link 'upper'"
    assert _where(d) == (37, 15)
    assert d.notes[0][0].line == 20
    # and so the elbow's child is gone
    assert diags.take_error("E0411").message == "joint 'elbow' refers to unknown child link 'lower'"


def test_bad_number(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace('<mass value="1"/>', '<mass value="one"/>'))
    d = diags.take_error("E0404")
    assert d.message == "'value' of <mass> in link 'upper' must be a number, got 'one'"
    assert _where(d) == (23, 20)


def test_revolute_joint_without_limit(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace(
        '<limit lower="-2" upper="2" effort="5" velocity="3"/>', ""))
    d = diags.take_error("E0421")
    assert d.message == "joint 'elbow' is revolute but has no <limit> with effort and velocity"
    assert _where(d) == (30, 16)


def test_unknown_joint_type(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace('type="revolute">\n    <origin xyz="0 0 0.4"/>',
                                            'type="revolut">\n    <origin xyz="0 0 0.4"/>'))
    d = diags.take_error("E0422")
    assert d.message == "joint 'elbow' has unknown type 'revolut'; did you mean 'revolute'?"
    assert _where(d) == (30, 29)


# -- meshes ---------------------------------------------------------------------------------

def test_missing_mesh(tmp_path: Path, diags: Diags) -> None:
    source = _urdf(tmp_path, diags, ARM_URDF.replace("meshes/tetra.stl", "meshes/gone.stl"))
    d = diags.take_error("E0602")
    assert d.message == (f"mesh file '{tmp_path}/meshes/gone.stl' of a visual of link 'base' "
                         "does not exist")
    assert (d.span.file, _where(d)) == (str(source), (10, 33))


def test_unknown_package(tmp_path: Path, diags: Diags) -> None:
    _urdf(tmp_path, diags, ARM_URDF.replace("meshes/tetra.stl", "package://nowhere/tetra.stl"))
    d = diags.take_error("E0654")
    assert d.message == ("package 'nowhere' was not found (searched the package map, ROS_PACKAGE_PATH, "
                         "AMENT_PREFIX_PATH, the Python environment and the folders above the model); "
                         "1 mesh file needs it, the first mesh 'package://nowhere/tetra.stl' of a "
                         "visual of link 'base'")
    assert d.notes == ()


def test_mesh_format_that_cannot_be_written(tmp_path: Path, diags: Diags) -> None:
    """The language only names formats mpc writes; an IR file can name any."""
    from mpc.compiler.driver import Options
    from mpc.compiler.front_end import load_program
    from mpc.ir.text import dump

    arm(tmp_path)
    spec = write(tmp_path / "model.yml", definition("arm.urdf", "stl"))
    program = load_program(spec, Diags(), Options())
    assert program is not None
    ir = tmp_path / "model.ir"
    ir.write_text(dump(program).replace('mesh_format="stl"', 'mesh_format="x3d"'))
    assert compile_file(ir, tmp_path / "out", diags).out is None
    d = diags.take_error("E0501")
    assert d.message == "writing 'x3d' meshes is not supported yet"
    assert _where(d) == (10, 7)


def test_bobj_meshes_read_back(tmp_path: Path) -> None:
    from mpc.core import bobj

    arm(tmp_path)
    spec = write(tmp_path / "model.yml", definition("arm.urdf", "bobj"))
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    mesh = bobj.loads((out / "meshes/bobj/tetra.bobj").read_bytes())
    assert len(mesh.faces) == 4 and abs(mesh.volume - 0.1**3 / 6) < 1e-9


def test_meshes_are_converted(tmp_path: Path) -> None:
    import trimesh

    arm(tmp_path)
    spec = write(tmp_path / "model.yml", definition("arm.urdf", "obj"))
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    converted = trimesh.load(out / "meshes/obj/tetra.obj", force="mesh")
    original = trimesh.load(tmp_path / "meshes/tetra.stl", force="mesh")
    assert len(converted.faces) == 4
    assert abs(converted.volume - original.volume) < 1e-9


# -- nothing already built is lost -----------------------------------------------------------

@pytest.mark.parametrize("breakage", ["<robot", "meshes/gone.stl"])
def test_failed_build_keeps_previous_output(tmp_path: Path, breakage: str) -> None:
    source = arm(tmp_path)
    spec = write(tmp_path / "model.yml", definition("arm.urdf", "stl"))
    good = compile_file(spec, tmp_path / "out", Diags()).out
    assert good is not None
    before = {p: p.read_bytes() for p in good.rglob("*") if p.is_file()}
    broken = ARM_URDF.replace("meshes/tetra.stl", breakage) if "/" in breakage else ARM_URDF[:-10]
    source.write_text(broken)
    sink = Diags()
    assert compile_file(spec, tmp_path / "out", sink).out is None
    assert sink.has_errors()
    after = {p: p.read_bytes() for p in good.rglob("*") if p.is_file()}
    assert after == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.urdf", "meshes", "model.yml", "out"]
