"""A program and its compiled output → the protocol of its model tests.

The tests run in the order the definition lists them; topological_self_consistency,
file_consistency and physical_validity run always (after the listed ones, when not listed).
A test that raises does not end the others: it fails with the exception as its reason.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable
from pathlib import Path

from mpc.checks import (  # noqa: F401  (registration)
    budgets,
    bullet,
    dynamics,
    limits,
    masses,
    pictures,
    plausibility,
    process,
    topology,
    validity,
)
from mpc.checks.compare_name import compare_name
from mpc.checks.models import Model, load_built, load_compare
from mpc.checks.pictures import VisualDiff
from mpc.checks.protocol import Protocol, Result, failed
from mpc.checks.registry import DYNAMICS_CHECKS, TESTS, Context
from mpc.core.diagnostics import Sink
from mpc.core.files import resolved
from mpc.ir.program import ModelTest, PdfExport, Program, TestPlan
from mpc.ir.robot import Robot

ALWAYS = ("topological_self_consistency", "file_consistency", "physical_validity")


def apply_program(program: Program, sink: Sink) -> Robot | None:
    """The robot the program describes (its inputs read, its ops run), or None."""
    from mpc.compiler.driver import Options
    from mpc.compiler.front_end import input_loader
    from mpc.compiler.ops_run import apply

    loader = input_loader(sink, Options(), (resolved(program.span.file),))
    return apply(program, sink, loader)


def run_model_tests(program: Program, built: Path, sink: Sink, *, workdir: Path,
                    robot: Robot | None = None) -> Protocol:
    """Run the tests of `program` on its compiled output `built`; clones go into `workdir`.

    robot: the program applied, when the caller has it (else it is built here); it says
    what the model should contain beyond URDF: cut joints, motors, submechanisms.
    """
    plan = program.test or TestPlan(span=program.span)
    if robot is None:
        quiet = Sink()  # the build reported these already
        robot = apply_program(program, quiet)
    new, new_problem = _load(load_built, program, built, robot)
    ctx = Context(program=program, plan=plan, sink=sink, new=new, new_problem=new_problem, robot=robot)
    protocol = Protocol(model=program.modelname)
    if plan.compare is not None:
        target = plan.compare
        where = compare_name(target, Path(program.span.file) if program.span.file else None)
        ctx.old, ctx.old_problem = _load(load_compare, target, workdir, where)
        if ctx.old is None:
            sink.error(target.span, "E0704", ctx.old_problem)
            protocol.compare = f"`{where}`, which could not be loaded"
        else:
            at = f" at commit `{ctx.old.commit[:12]}`" if ctx.old.commit else ""
            protocol.compare = f"`{where}`{at}"
            waive = target.ignore_failing_tests_for
            if waive and ctx.old.commit.startswith(waive):
                protocol.waiver = (f"the compare model is at commit {ctx.old.commit[:12]}, which "
                                   "ignore_failing_tests_for names")
    if new is None:
        sink.error(program.span, "E0705", f"cannot test '{program.modelname}': {new_problem}")
    tests = list(plan.tests)
    listed = {t.name for t in tests if not t.dynamics}
    tests += [ModelTest(name=name, span=plan.span) for name in ALWAYS if name not in listed]
    for test in tests:
        protocol.add(_run(ctx, test))
    if ctx.old is not None and ctx.new is not None:
        protocol.changes = _changes(ctx)
        protocol.pictures = _pictures(ctx)
    return protocol


def _changes(ctx: Context) -> tuple[str, ...]:
    """What `mpc diff` says changed since the compare model; a bug in it is one change."""
    try:
        from mpc.checks.diff_models import diff

        return tuple(c.text for c in diff(ctx.compare.robot, ctx.built.robot, ctx.tol).changes)
    except Exception as e:
        return (f"the diff could not be made: {_bug(e)}",)


def _pictures(ctx: Context) -> VisualDiff:
    """The visual diff against the release (checks/pictures.py); a bug in it is its reason."""
    try:
        tree = any(isinstance(e, PdfExport) and not e.submodel for e in ctx.program.exports)
        return pictures.draw(ctx.compare.robot, ctx.built.robot, ctx.tol,
                             pictures.render_export(ctx.program.exports), ctx.sink, tree=tree)
    except Exception as e:
        return VisualDiff(problem=_bug(e))


def _load(loader: Callable[..., tuple[Model | None, str]], *args: object) -> tuple[Model | None, str]:
    """A model loader's answer; should it raise (a bug in mpc), the exception is the reason,
    so that the tests still run and the protocol is still written."""
    try:
        return loader(*args)
    except Exception as e:
        return None, f"{_bug(e)}"


def _bug(e: Exception) -> str:
    where = traceback.extract_tb(e.__traceback__)[-1]
    return (f"a bug in mpc, please report it: {type(e).__name__}: {e} at "
            f"{Path(where.filename).name}:{where.lineno}")


def _run(ctx: Context, test: ModelTest) -> Result:
    fn = (DYNAMICS_CHECKS if test.dynamics else TESTS).get(test.name)
    if fn is None:  # the schema knows it, no check implements it
        return failed(test.name, f"mpc has no implementation of test '{test.name}'")
    try:
        return fn(ctx, test)
    except Exception as e:  # a bug in a check must not end the other tests
        return failed(test.name, f"the test itself failed ({_bug(e)})")
