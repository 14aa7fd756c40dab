"""Hand-written IR (issue 30.7): a line may leave out its `@ file:line:col-…` span, as
grammar/ir.lark allows, and then the line's own place in the IR file stands in for it; what
`mpc check` and `mpc compile` report about such a line points at the line.
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
