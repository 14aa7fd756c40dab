"""Hand-written IR (issue 30.7): a line may leave out its `@ file:line:col-…` span, as
grammar/ir.lark allows, and then the line's own place in the IR file stands in for it; what
`mpc check` and `mpc compile` report about such a line points at the line. A program written
in another order than the language's gets W0330 only when it is reordered, not when it is
refused (E0330).
"""

from __future__ import annotations

from pathlib import Path

from mpc.core.diagnostics import Sink
from mpc.core.span import Span
from mpc.ir.text import parse
from tests.conftest import write
from tests.mpc_command import mpc

ARM = ('<robot name="arm"><link name="base"/><link name="upper"/><joint name="j" type="fixed">'
       '<parent link="base"/><child link="upper"/></joint></robot>\n')


def _arm_ir(folder: Path, *ops: str) -> str:
    write(folder / "arm.urdf", ARM)
    return "\n".join(["# mpc ir 1", 'program robotname="arm" modelname="arm"',
                      f'input arm kind="basefile" path=path("{folder / "arm.urdf"}")',
                      'op load_model input="arm"', *ops, 'export urdf mesh_format="input_type"']) + "\n"


def test_a_line_without_a_span_has_its_own_place_as_span(tmp_path: Path) -> None:
    text = _arm_ir(tmp_path, 'op take_leaf link="upper"', 'op set_robot_name name="r" @ arm.yml:3:5-3:9')
    sink = Sink()
    program = parse(text, "hand.ir", sink)
    assert program is not None and list(sink) == []
    assert program.span == Span("hand.ir", 2, 1, 2, 40)
    assert program.inputs["arm"].span.line == 3
    assert [op.span for op in program.ops] == [
        Span("hand.ir", 4, 1, 4, 26), Span("hand.ir", 5, 1, 5, 26), Span("arm.yml", 3, 5, 3, 9)]
    assert program.exports[0].span == Span("hand.ir", 7, 1, 7, 37)


def test_check_of_hand_written_ir_points_at_the_line(tmp_path: Path) -> None:
    write(tmp_path / "arm.ir", _arm_ir(tmp_path, 'op take_leaf link="uper"'))
    done = mpc("check", "arm.ir", cwd=tmp_path)
    assert (done.returncode, done.stderr.splitlines()[0]) == (
        1, "arm.ir:5:1: error[E0310]: take_leaf refers to unknown link 'uper'; did you mean 'upper'?")


def test_compile_of_hand_written_ir_builds_the_model(tmp_path: Path) -> None:
    write(tmp_path / "arm.ir", _arm_ir(tmp_path, 'op take_leaf link="upper"'))
    done = mpc("compile", "arm.ir", "-o", "out", cwd=tmp_path)
    assert (done.returncode, done.stderr) == (0, "")
    urdf = next((tmp_path / "out").rglob("*.urdf")).read_text()
    assert '<link name="upper"' in urdf and '<link name="base"' not in urdf


def test_a_span_field_and_no_at_is_the_field(tmp_path: Path) -> None:
    text = _arm_ir(tmp_path, 'op take_leaf link="upper" span=span("a.yml", 9, 1, 9, 4)')
    program = parse(text, "hand.ir", Sink())
    assert program is not None and program.ops[1].span == Span("a.yml", 9, 1, 9, 4)


LINE = ('<robot name="arm"><link name="base"/><link name="upper"/><link name="lower"/><link name="hand"/>'
        '<joint name="j1" type="fixed"><parent link="base"/><child link="upper"/></joint>'
        '<joint name="j2" type="fixed"><parent link="upper"/><child link="lower"/></joint>'
        '<joint name="j3" type="fixed"><parent link="lower"/><child link="hand"/></joint></robot>\n')
MOVED = ['op take_leaf link="upper"', 'op remove_beyond links=["lower"]']  # reordered, with W0330
CLASH = ['op add_pose name="home" positions={}',
         'op transform_link link="upper" xyz=[0.1, 0.0, 0.0]']  # refused, E0330


def _line_ir(folder: Path, *ops: str) -> Path:
    write(folder / "line.urdf", LINE)
    return write(folder / "line.ir", "\n".join([
        "# mpc ir 1", 'program robotname="line" modelname="line"',
        f'input line kind="basefile" path=path("{folder / "line.urdf"}")', 'op load_model input="line"',
        *ops, 'export urdf mesh_format="input_type"']) + "\n")


def test_a_reordered_program_is_checked_with_w0330(tmp_path: Path) -> None:
    _line_ir(tmp_path, *MOVED)
    done = mpc("check", "line.ir", "--format", "gcc", cwd=tmp_path)
    assert (done.returncode, done.stderr.splitlines()) == (0, [
        "line.ir:6:1: warning: remove_beyond (line 6) runs before take_leaf (line 5), "
        "in the language's order [W0330]"])


def test_a_refused_program_gets_no_w0330(tmp_path: Path) -> None:
    _line_ir(tmp_path, *MOVED, *CLASH)
    done = mpc("check", "line.ir", "--format", "gcc", cwd=tmp_path)
    assert (done.returncode, done.stderr.splitlines()) == (1, [
        "line.ir:8:1: error: transform_link (line 8) is written after add_pose (line 7), but the "
        "language runs it first, and the two do not give the same robot in either order [E0330]"])
