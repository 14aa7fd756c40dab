"""The test registry and what every test sees: both models, the tolerances, the configuration.

Each test is a function registered under its definition name (`@register("compare_com",
dynamics=True, needs="both")`), taking the context and its `ModelTest` entry and returning
a Result. It runs only when the models it measures are there (`ctx.built`, and with
needs="both" `ctx.compare`); else its result says why.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field
from typing import Literal

from mpc.checks.models import Model
from mpc.checks.protocol import Result, Tolerance, failed, skipped
from mpc.core.diagnostics import Sink
from mpc.core.record import record
from mpc.ir.program import ModelTest, Program, TestPlan, Tolerances
from mpc.ir.robot import Robot

Test = Callable[["Context", ModelTest], Result]
TESTS: dict[str, Test] = {}
DYNAMICS_CHECKS: dict[str, Test] = {}


def register(name: str, dynamics: bool = False, needs: Literal["built", "both"] = "built"
             ) -> Callable[[Test], Test]:
    """Register a test under its definition name (a dynamics check: inside hyrodynChecks).

    needs: the models it measures. Without them it does not run: it fails when the compiled
    model (or a configured compare model) cannot be loaded, and is skipped when it needs a
    compare model and the definition has none (Context.need_built, Context.need_both)."""
    def add(fn: Test) -> Test:
        def run(ctx: Context, test: ModelTest) -> Result:
            missing = ctx.need_both(test.name) if needs == "both" else ctx.need_built(test.name)
            return missing if missing is not None else fn(ctx, test)
        run.__doc__ = fn.__doc__
        (DYNAMICS_CHECKS if dynamics else TESTS)[name] = run
        return fn
    return add


@record(frozen=False)
class Context:
    """What the tests of one model share.

    new: the compiled model (None with `new_problem`). old: the compare model (None with
    `old_problem`, "" when no compare model is configured). robot: the program applied (the
    robot the ops produced), for process_double_check. configuration: joint values by name
    that move_hyrodyn_model set for the dynamics checks after it; `angle` for every joint.
    """

    program: Program
    plan: TestPlan
    sink: Sink
    new: Model | None
    new_problem: str = ""
    old: Model | None = None
    old_problem: str = ""
    robot: Robot | None = None
    configuration: dict[str, float] = field(default_factory=dict)

    @property
    def tol(self) -> Tolerances:
        return self.plan.tolerances

    def bound(self, name: str, unit: str) -> tuple[Tolerance]:
        """The tolerance `name` (mass, distance, rad, default) as a result's bound in `unit`."""
        return (Tolerance(name, getattr(self.tol, name), unit),)

    @property
    def built(self) -> Model:
        """The compiled model, for a test registered as needing it (so it is there)."""
        assert self.new is not None
        return self.new

    @property
    def compare(self) -> Model:
        """The compare model, for a test registered with needs="both"."""
        assert self.old is not None
        return self.old

    def need_built(self, name: str) -> Result | None:
        """A failed result when the compiled model could not be read."""
        return None if self.new is not None else failed(name, f"the compiled model cannot be loaded: "
                                                         f"{self.new_problem}")

    def need_both(self, name: str) -> Result | None:
        """A failed or skipped result when a model to compare is missing. Without a
        compare_model the test is skipped; with one that cannot be loaded it fails."""
        problem = self.need_built(name)
        if problem is not None:
            return problem
        if self.old is not None:
            return None
        if self.plan.compare is None:
            return skipped(name, "no compare_model in the definition")
        return failed(name, f"the compare model cannot be loaded: {self.old_problem}")
