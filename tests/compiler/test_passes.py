"""The passes of compiler/passes/: golden before/after cases, and invariants after every pass.

tests/fixtures/passes/<pass>.txt holds the cases of one pass (the format is explained at the
top of order_ops.txt): the ops as written, the ops the pass leaves and its diagnostics. The
input models are trees of link names, written as URDF files in a temporary folder; the passes
see their names through `PassContext.input_names`, as `mpc check` does.

After every pass that reports no error, the program it leaves must hold: every name an op
reads resolves, the parts form one tree (each loaded once, attached once into a part that
exists, only `root` left), and the ops are in the language's order (once order_ops ran).
"""

from __future__ import annotations

import contextlib
import io
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

from mpc.compiler.passes import PASSES, PassContext, order_ops
from mpc.compiler.passes.check_names import symbolic
from mpc.compiler.passes.order_ops import language_order
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.names import Names
from mpc.ir.ops import ROOT, Attach, LoadModel, import_all
from mpc.ir.program import Program
from mpc.ir.text import dump, parse

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "passes"
SPECS = Path(__file__).resolve().parents[2] / "specs" / "examples"
PASS_NAMES = [p.__name__ for p in PASSES]


@dataclass(frozen=True)
class Case:
    """One golden case: title, input trees ((parent, child) edges by model), ops in, ops out."""

    title: str
    trees: dict[str, list[tuple[str, str]]]
    missing: frozenset[str]
    ops: list[str]
    out: list[str]
    diagnostics: list[str]


def _cases(name: str) -> list[Case]:
    text = (FIXTURES / f"{name}.txt").read_text()
    cases = []
    for block in re.split(r"\n\s*\n", text):
        lines = block.strip().split("\n")
        if not lines[0].startswith("# title: "):
            continue
        trees: dict[str, list[tuple[str, str]]] = {}
        missing: set[str] = set()
        section, parts = "ops", {"ops": [], "out": [], "diagnostics": []}  # type: ignore[var-annotated]
        for line in lines[1:]:
            if m := re.fullmatch(r"# input (\w+): (.*)", line):
                trees[m.group(1)] = [tuple(e.strip().split(">")) for e in m.group(2).split(",")]  # type: ignore[misc]
            elif m := re.fullmatch(r"# missing: (\w+)", line):
                missing.add(m.group(1))
            elif m := re.fullmatch(r"# (out|diagnostics):", line):
                section = m.group(1)
            else:
                parts[section].append(line)
        cases.append(Case(lines[0][len("# title: "):], trees, frozenset(missing), parts["ops"],
                          parts["out"], parts["diagnostics"]))
    return cases


def _urdf(edges: list[tuple[str, str]]) -> str:
    links = "".join(f'<link name="{n}"/>' for n in dict.fromkeys(n for edge in edges for n in edge))
    joints = "".join(f'<joint name="{p}2{c}" type="fixed"><parent link="{p}"/><child link="{c}"/></joint>'
                     for p, c in edges)
    return f'<robot name="r">{links}{joints}</robot>\n'


def _names(edges: list[tuple[str, str]]) -> Names:
    children = {c for _, c in edges}
    links = frozenset(n for edge in edges for n in edge)
    root = next(n for n in (p for p, _ in edges) if n not in children)
    return Names(links=links, joints={f"{p}2{c}": (p, c) for p, c in edges}, root=root)


def _program(case: Case, folder: Path, sink: Sink) -> Program:
    lines = ["# mpc ir 1", 'program robotname="r" modelname="r" @ t.ir:0:1-0:2']
    for name, edges in case.trees.items():
        if name not in case.missing:
            (folder / f"{name}.urdf").write_text(_urdf(edges))
        lines.append(f'input {name} kind="basefile" path=path("{folder / name}.urdf") @ t.ir:0:1-0:2')
    lines += [f"{op} @ t.ir:{i}:1-{i}:2" for i, op in enumerate(case.ops, 1)]
    program = parse("\n".join(lines) + "\n", "t.ir", sink)
    assert program is not None, [d.message for d in sink]
    return program


def _ops(program: Program) -> list[str]:
    return [re.sub(r" @ \S+$", "", line) for line in dump(program).split("\n") if line.startswith("op ")]


def _context(case: Case, sink: Sink) -> PassContext:
    names = {name: _names(edges) for name, edges in case.trees.items()}
    return PassContext(sink, lambda inp: names.get(inp.name), Severity.ERROR)


def _unresolved(program: Program, ctx: PassContext) -> list[str]:
    sink = Sink()
    symbolic(program, PassContext(sink, ctx.input_names, ctx.later))
    return [d.message for d in sink if d.severity is Severity.ERROR]


def check_invariants(before: Program, after: Program, ctx: PassContext, ordered: bool) -> None:
    """A pass keeps names resolving; once ordered, the parts form one tree and the phases
    are in the language's order."""
    if not _unresolved(before, ctx):
        assert not _unresolved(after, ctx)
    if not ordered:
        return
    alive: set[str] = set()
    attached: set[str] = set()
    for op in after.ops:
        if isinstance(op, LoadModel):
            assert op.part not in alive and op.part not in attached, f"{op.part} loaded twice"
            alive.add(op.part)
            continue
        assert set(op.parts()) <= alive, f"{op.kind} on {op.parts()}, but the parts are {alive}"
        if isinstance(op, Attach):
            alive.discard(op.child)
            attached.add(op.child)
    assert alive <= {ROOT}, f"parts never attached: {alive - {ROOT}}"
    assert all(a is b for a, b in zip(language_order(after.ops), after.ops, strict=True))


CASES = [(name, case) for name in PASS_NAMES for case in _cases(name)]


@pytest.mark.parametrize(("name", "case"), CASES, ids=[f"{n}: {c.title}" for n, c in CASES])
def test_pass(name: str, case: Case, tmp_path: Path) -> None:
    sink = Sink()
    program = _program(case, tmp_path, sink)
    ctx = _context(case, sink)
    after = dict((p.__name__, p) for p in PASSES)[name](program, ctx)
    assert _ops(after) == case.out
    shown = [f"{d.code} {d.span.line} {d.message}".replace(str(tmp_path), "<tmp>") for d in sink]
    assert shown == case.diagnostics
    if after is not program:
        assert _ops(program) == case.ops, "a pass changed its input"
    elif case.out != case.ops:
        pytest.fail("the pass returned its input but the case expects a change")
    if not sink.has_errors():
        check_invariants(program, after, ctx, ordered=PASS_NAMES.index(name) >= PASS_NAMES.index("order_ops"))


def test_every_pass_has_golden_cases() -> None:
    assert {name for name, _ in CASES} == set(PASS_NAMES)
    assert sorted(p.stem for p in FIXTURES.glob("*.txt")) == sorted(PASS_NAMES)


@pytest.mark.parametrize(("name", "case"), CASES, ids=[f"{n}: {c.title}" for n, c in CASES])
def test_invariants_hold_after_every_pass(name: str, case: Case, tmp_path: Path) -> None:
    """The whole list of passes, as the driver runs them, on every golden case's program."""
    sink = Sink()
    program = _program(case, tmp_path, sink)
    ctx = _context(case, sink)
    for i, p in enumerate(PASSES):
        errors = sink.error_count
        before, program = program, p(program, ctx)
        if sink.error_count > errors:
            return
        check_invariants(before, program, ctx, ordered=i >= PASSES.index(order_ops))


def test_every_op_declares_its_phase() -> None:
    undeclared = [kind for kind, cls in import_all().items() if not hasattr(cls, "PHASE")]
    assert not undeclared


@pytest.mark.parametrize("golden", sorted(SPECS.glob("*.ir")), ids=lambda p: p.stem)
def test_specs_golden_programs_are_in_the_language_order(golden: Path) -> None:
    """What lowering writes is in order already: order_ops returns it as it is."""
    sink = Sink()
    program = parse(golden.read_text().replace("<specs>", str(SPECS)), golden.name, sink)
    assert program is not None, [d.message for d in sink]
    assert order_ops(program, PassContext(sink)) is program
    assert not list(sink)


def _arm_definition(folder: Path, assemble: str) -> Path:
    """A definition of the arm (tests/fixtures.py) with this `assemble` section."""
    from tests.conftest import write
    from tests.fixtures import ARM_URDF

    write(folder / "arm.urdf", ARM_URDF)
    return write(folder / "arm.yml", "model:\n  robotname: arm\n  modelname: arm\n"
                 "  input_models:\n    arm: {basefile: arm.urdf}\n" + assemble)


def test_one_clash_of_many_names_is_one_report(tmp_path: Path) -> None:
    """Attaching a model to itself unrenamed: one E0304 per kind of name, not one per name."""
    from mpc.cli.check import check_file
    from mpc.compiler.options import Options

    definition = _arm_definition(tmp_path, "  assemble:\n    model: arm\n    children:\n"
                                 "      - model: arm\n        joint: {parent: lower, name: wrist}\n")

    sink = Sink()
    check_file(definition, sink, Options())
    assert [(d.code, d.message) for d in sink if d.code == "E0304"] == [
        ("E0304", "3 links ('base', 'lower', 'upper') would exist twice after attaching: in 'arm' "
                  "and in 'arm'; rename one with name_editing"),
        ("E0304", "2 joints ('elbow', 'shoulder') would exist twice after attaching: in 'arm' "
                  "and in 'arm'; rename one with name_editing")]


def test_emit_ir_lowered_is_before_the_passes(tmp_path: Path) -> None:
    """`--emit ir-lowered` keeps the dead remove_beyond that `--emit ir` drops."""
    from mpc.cli.main import main

    definition = _arm_definition(
        tmp_path, "  assemble: {model: arm, remove_beyond: lower, take_leaf: upper}\n")
    printed = {}
    for emit in ("ir", "ir-lowered"):
        out, errors = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(errors):
            assert main(["compile", str(definition), "--emit", emit]) == 0
        ops = [re.sub(r" (spans=\{.*\} )?@.*", "", line) for line in out.getvalue().split("\n")
               if line.startswith("op ")]
        printed[emit] = (ops, errors.getvalue())
    assert printed["ir-lowered"][0] == ['op load_model input="arm"', 'op remove_beyond links=["lower"]',
                                        'op take_leaf link="upper"', 'op set_robot_name name="arm"']
    assert printed["ir"][0] == ['op load_model input="arm"', 'op take_leaf link="upper"',
                                'op set_robot_name name="arm"']
    assert ("warning[W0331]: remove_beyond (line 6) has no effect: after take_leaf (line 6) the robot "
            "is the same without it; it is dropped") in printed["ir"][1]
    assert printed["ir-lowered"][1] == ""
