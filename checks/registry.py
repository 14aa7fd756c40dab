"""The test registry and what every test sees: both models, the tolerances, the configuration.

Each test is a function registered under its definition name (`@register("compare_com",
dynamics=True)`), taking the context and its `ModelTest` entry and returning a Result.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from mpc.checks.models import Model
from mpc.checks.protocol import Result, Tolerance, failed, skipped
from mpc.compiler.diagnostics import Sink
from mpc.ir.program import ModelTest, Program, TestPlan, Tolerances
from mpc.ir.robot import Robot

Test = Callable[["Context", ModelTest], Result]
TESTS: dict[str, Test] = {}
DYNAMICS_CHECKS: dict[str, Test] = {}


def register(name: str, dynamics: bool = False) -> Callable[[Test], Test]:
    """Register a test under its definition name (a dynamics check: inside hyrodynChecks)."""
    def add(fn: Test) -> Test:
        (DYNAMICS_CHECKS if dynamics else TESTS)[name] = fn
        return fn
    return add


@dataclass
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

    def need_new(self, name: str) -> Result | None:
        """A failed result when the compiled model could not be read."""
        return None if self.new is not None else failed(name, f"the compiled model cannot be loaded: "
                                                         f"{self.new_problem}")

    def need_both(self, name: str) -> Result | None:
        """A failed or skipped result when a model to compare is missing. Without a
        compare_model the test is skipped; with one that cannot be loaded it fails."""
        problem = self.need_new(name)
        if problem is not None:
            return problem
        if self.old is not None:
            return None
        if self.plan.compare is None:
            return skipped(name, "no compare_model in the definition")
        return failed(name, f"the compare model cannot be loaded: {self.old_problem}")
