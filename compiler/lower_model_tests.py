"""The `test` section (AST) → ir.TestPlan: tests with checked arguments, tolerances merged
with the defaults, the compare model, and the expected values of `test_data_file`.

It reads `test_data_file` (a small YAML file) but no model and no repository.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from mpc.compiler.expr import evaluate
from mpc.compiler.schema.release import TestSection
from mpc.core.diagnostics import Sink
from mpc.core.files import resolved
from mpc.core.span import Span
from mpc.ir.program import DENSITY, FACTOR, CompareTarget, ModelTest, TestPlan, Tolerances

# Tests that take a pair of links [left, right] (and optionally a mirror plane).
PAIR_TESTS = frozenset({"symmetry_check_masses", "symmetry_check", "symmetry_check_torques"})
# Budgets: a test that fails when a figure of the model exceeds its limit (the argument, in these units).
BUDGETS = {"max_mesh_faces": "faces", "max_mesh_bytes": "bytes",
           "max_collisions_per_link": "collision shapes"}
# Tests whose argument is optional: the others take none.
_WITH_ARGUMENT = PAIR_TESTS | set(BUDGETS) | {"total_mass", "compare_link_positions", "move_hyrodyn_model",
                                         "physical_validity", "compare_torques", "joint_limits"}
_LIMIT_FIGURES = ("position", "velocity", "effort")
_UNITS = ("deg", "rad")


class _TestLowering:
    def __init__(self, section: TestSection, base_dir: Path, sink: Sink) -> None:
        self.section, self.base_dir, self.sink = section, base_dir, sink

    def span(self, *path: str | int) -> Span:
        return self.section.value_span(*path)

    def number(self, value: Any, span: Span, what: str) -> float | None:
        return evaluate(value, span, self.sink, what=what)

    def tolerances(self) -> Tolerances:
        tol = self.section.tolerances
        if tol is None:
            return Tolerances()
        values = {}
        for key in ("default", "mass", "rad", "distance"):
            value = evaluate(getattr(tol, key), tol.value_span(key), self.sink, what=f"tolerance '{key}'")
            if value is not None and value < 0:
                self.sink.error(tol.value_span(key), "E0701", f"tolerance '{key}' must not be negative, "
                                f"got {value:g}")
                value = None
            if value is not None:
                values[key] = value
        return Tolerances(**values)

    def compare(self) -> CompareTarget | None:
        c = self.section.compare_model
        if c is None:
            return None
        if (c.git is None) == (c.path is None):
            self.sink.error(c.span, "E0701", "compare_model needs either 'git' (a repository) or "
                            "'path' (a folder or model file), not " + ("both" if c.git else "neither"))
            return None
        if c.path is not None and (c.branch or c.commit):
            key = "branch" if c.branch else "commit"
            self.sink.error(c.key_span(key), "E0701", f"'{key}' needs a 'git' compare model; "
                            "'path' names a folder as it is")
            return None
        waive = self.waiver(c.ignore_failing_tests_for, c.path is not None)
        if waive is None:
            return None
        path = None
        if c.path is not None:
            file = c.value_span("path").file
            folder = resolved(file).parent if file else self.base_dir
            path = resolved(folder / c.path)
        git = c.git or ""
        if git and "://" not in git and "@" not in git.split("/")[0] and not Path(git).is_absolute():
            git = str(resolved(self.base_dir / git))  # a local repository next to the definition
        return CompareTarget(span=c.span, git=git, path=path, branch=c.branch or "", commit=c.commit or "",
                             model_in_repo=c.model_in_repo or "",
                             submechanisms_in_repo=c.submechanisms_in_repo or "",
                             ignore_failing_tests_for=waive)

    def waiver(self, value: object, with_path: bool) -> str | None:
        """`ignore_failing_tests_for`, lower case ("" when not given), or None after an error:
        it names a commit of a git compare model, so it is 4 to 40 hex digits and needs `git`
        (a shorter prefix would waive failures at one commit in sixteen or more)."""
        if value is None or value == "":
            return ""
        span = self.section.compare_model.value_span("ignore_failing_tests_for")  # type: ignore[union-attr]
        waive = str(value).strip().lower()
        if with_path:
            self.sink.error(span, "E0701", "'ignore_failing_tests_for' names a commit of a 'git' compare "
                            "model; a 'path' has no commits")
            return None
        if not re.fullmatch(r"[0-9a-f]{4,40}", waive):
            self.sink.error(span, "E0701", "'ignore_failing_tests_for' is a commit of the compare "
                            "repository: "
                            f"4 to 40 hex digits, quoted (e.g. \"82b92a86\"), got {value!r}")
            return None
        return waive

    def expected_mass(self) -> float | None:
        written = self.section.test_data_file
        path = self.base_dir / (written or "test_data.yml")
        if written is None and not path.is_file():
            return None
        span = self.span("test_data_file") if written else self.section.span
        from mpc.core import yaml_source as source
        from mpc.core.files import input_problem, project_root

        if path.is_file() and (why := input_problem(path, (project_root(self.base_dir),))):
            self.sink.error(span, "E0650", f"test_data_file '{written or path.name}' is not read: {why}")
            return None
        doc = source.load(path, self.sink) if path.is_file() else None
        if doc is None:
            if not path.is_file():
                self.sink.error(span, "E0702", f"test_data_file '{written}' does not exist")
            return None
        data = doc.data.get("test_data") if isinstance(doc.data, dict) else None
        if not isinstance(data, dict) or "expected_mass" not in data:
            return None
        return evaluate(data["expected_mass"], doc.value_span(("test_data", "expected_mass")), self.sink,
                        what="expected_mass")

    def tests(self) -> tuple[ModelTest, ...]:
        out: list[ModelTest] = []
        for i, item in enumerate(self.section.tests):
            name, arg = _split(item)
            if name == "hyrodynChecks":
                for k, check in enumerate(arg):
                    inner, inner_arg = _split(check)
                    test = self.test(inner, inner_arg, self.span("tests", i, "hyrodynChecks", k),
                                     dynamics=True)
                    if test is not None:
                        out.append(test)
                continue
            test = self.test(name, arg, self.span("tests", i), dynamics=False)
            if test is not None:
                out.append(test)
        return tuple(out)

    def test(self, name: str, arg: Any, span: Span, dynamics: bool) -> ModelTest | None:
        what = f"test '{name}'"
        test = ModelTest(name=name, span=span, dynamics=dynamics)
        if arg is None:
            if name in PAIR_TESTS or name in BUDGETS or name == "move_hyrodyn_model":
                self.sink.error(span, "E0703", f"{what} needs an argument: {_NEEDS[name]}")
                return None
            return test
        if name not in _WITH_ARGUMENT:
            self.sink.error(span, "E0703", f"{what} takes no argument")
            return None
        if name == "total_mass":
            value = self.number(arg, span, f"{what} expected mass")
            if value is not None and value < 0:
                self.sink.error(span, "E0703", f"{what}: the expected mass must not be negative, "
                                f"got {value:g}")
                return None
            return None if value is None else ModelTest(name=name, span=span, dynamics=dynamics, value=value)
        if name == "physical_validity":
            return self.validity(span, arg)
        if name in BUDGETS:
            return self.budget(name, span, arg)
        if name == "joint_limits":
            return self.joint_limits(span, arg)
        if name in ("compare_link_positions", "compare_torques"):
            links = [arg] if isinstance(arg, str) else arg
            if not isinstance(links, list) or not all(isinstance(x, str) for x in links):
                self.sink.error(span, "E0703", f"{what} takes a list of "
                                f"{'link' if name == 'compare_link_positions' else 'joint'} names")
                return None
            return ModelTest(name=name, span=span, dynamics=dynamics, links=tuple(links))
        if name in PAIR_TESTS:
            return self.pair(test, arg)
        return self.configuration(test, arg)

    def validity(self, span: Span, arg: Any) -> ModelTest | None:
        """physical_validity: `error` or `warning`, or {severity, density: [min, max] kg/m³,
        inertia_factor} (the plausibility bounds; checks/validity.py)."""
        what = "test 'physical_validity'"
        settings = arg if isinstance(arg, dict) else {"severity": arg}
        unknown = set(settings) - {"severity", "density", "inertia_factor"}
        if unknown:
            self.sink.error(span, "E0703", f"{what}: unknown key '{sorted(unknown)[0]}' (it takes "
                            "'severity', 'density' and 'inertia_factor')")
            return None
        severity = settings.get("severity", "warning")
        if severity not in ("error", "warning"):
            self.sink.error(span, "E0703", f"{what}: the argument is 'error' (findings fail the "
                            f"test) or 'warning', got {severity!r}")
            return None
        density, factor = DENSITY, FACTOR
        if "density" in settings:
            values = settings["density"]
            got = [self.number(v, span, f"{what} density") for v in values] \
                if isinstance(values, list) else []
            if len(got) != 2 or None in got or not 0 <= got[0] < got[1]:  # type: ignore[operator]
                self.sink.error(span, "E0703", f"{what}: 'density' is the range of plausible densities "
                                "[min, max] in kg/m³, 0 ≤ min < max, e.g. [100, 25000]")
                return None
            density = (got[0], got[1])
        if "inertia_factor" in settings:
            value = self.number(settings["inertia_factor"], span, f"{what} inertia_factor")
            if value is None or value < 1:
                if value is not None:
                    self.sink.error(span, "E0703", f"{what}: 'inertia_factor' is at least 1, got {value:g}")
                return None
            factor = value
        return ModelTest(name="physical_validity", span=span, as_error=severity == "error", density=density,
                         inertia_factor=factor)

    def budget(self, name: str, span: Span, arg: Any) -> ModelTest | None:
        """A budget's limit: a whole number ≥ 0 (faces, bytes, collisions), an expression allowed."""
        value = self.number(arg, span, f"test '{name}' limit")
        if value is None:
            return None
        if value < 0 or not float(value).is_integer():  # inf and nan too
            self.sink.error(span, "E0703", f"test '{name}': the limit is a whole number of "
                            f"{BUDGETS[name]}, at least 0, got {value:g}")
            return None
        return ModelTest(name=name, span=span, value=float(value))

    def joint_limits(self, span: Span, arg: Any) -> ModelTest | None:
        """joint_limits: {position, velocity, effort} (absolute bounds; each replaces the tolerance
        it defaults to) and mirrored: [left, right] (the name parts of mirrored joints)."""
        what = "test 'joint_limits'"
        if not isinstance(arg, dict):
            self.sink.error(span, "E0703", f"{what} takes a mapping {{position, velocity, effort, "
                            f"mirrored}}, got {arg!r}")
            return None
        unknown = set(arg) - {*_LIMIT_FIGURES, "mirrored"}
        if unknown:
            self.sink.error(span, "E0703", f"{what}: unknown key '{sorted(unknown, key=str)[0]}' (it takes "
                            "'position', 'velocity', 'effort' and 'mirrored')")
            return None
        bounds: dict[str, float] = {}
        for key in _LIMIT_FIGURES:
            if key in arg:
                value = self.number(arg[key], span, f"{what} {key}")
                if value is None:
                    return None
                if value < 0:
                    self.sink.error(span, "E0703", f"{what}: '{key}' must not be negative, got {value:g}")
                    return None
                bounds[key] = value
        mirrored = arg.get("mirrored")
        if mirrored is not None:
            if not (isinstance(mirrored, list) and len(mirrored) == 2 and all(
                    isinstance(x, str) and x for x in mirrored) and mirrored[0] != mirrored[1]):
                self.sink.error(span, "E0703", f"{what}: 'mirrored' is the two parts of the names that "
                                f"tell mirrored joints apart, e.g. [left, right], got {mirrored!r}")
                return None
            mirrored = (mirrored[0], mirrored[1])
        return ModelTest(name="joint_limits", span=span, limit_tolerances=bounds or None, mirrored=mirrored)

    def pair(self, test: ModelTest, arg: Any) -> ModelTest | None:
        what = f"test '{test.name}'"
        plane = (0.0, 1.0, 0.0)
        if isinstance(arg, dict):
            unknown = set(arg) - {"links", "plane"}
            if unknown:
                self.sink.error(test.span, "E0703", f"{what}: unknown key '{sorted(unknown)[0]}' "
                                "(it takes 'links' and 'plane')")
                return None
            if "plane" in arg:
                values = arg["plane"]
                got = [self.number(v, test.span, f"{what} plane") for v in values] \
                    if isinstance(values, list) else []
                if len(got) != 3 or None in got or all(v == 0 for v in got):
                    self.sink.error(test.span, "E0703", f"{what}: 'plane' is the normal of the mirror "
                                    "plane, three numbers not all zero, e.g. [0, 1, 0]")
                    return None
                plane = tuple(got)
            arg = arg.get("links")
        if not isinstance(arg, list) or len(arg) != 2 or not all(isinstance(x, str) for x in arg):
            self.sink.error(test.span, "E0703", f"{what} needs two link names [left, right], got {arg!r}")
            return None
        if arg[0] == arg[1]:
            self.sink.error(test.span, "E0703", f"{what} compares two different links; both are '{arg[0]}'")
            return None
        return ModelTest(name=test.name, span=test.span, dynamics=test.dynamics, links=tuple(arg),
                         plane=plane)

    def configuration(self, test: ModelTest, arg: Any) -> ModelTest | None:
        """move_hyrodyn_model: one value, a list (one per joint) or a mapping by joint name."""
        what = f"test '{test.name}'"
        base = {"name": test.name, "span": test.span, "dynamics": test.dynamics}
        if isinstance(arg, dict):
            values = {str(k): self.number(v, test.span, f"{what} '{k}'") for k, v in arg.items()}
            if None in values.values():
                return None
            return ModelTest(**base, joint_angles=values)  # type: ignore[arg-type]
        if isinstance(arg, list) and not (len(arg) == 2 and arg[0] in _UNITS):
            angles = [self.number(v, test.span, f"{what}[{i}]") for i, v in enumerate(arg)]
            return None if None in angles else ModelTest(**base, angles=tuple(angles))  # type: ignore[arg-type]
        value = self.number(arg, test.span, what)
        return None if value is None else ModelTest(**base, angle=value)


_NEEDS = {
    "symmetry_check_masses": "two link names [left, right]",
    "symmetry_check": "two link names [left, right]",
    "symmetry_check_torques": "two link names [left, right]",
    "move_hyrodyn_model": "a joint value, a list of values or a mapping {joint: value}",
    "max_mesh_faces": "the largest number of faces of a mesh",
    "max_mesh_bytes": "the largest total size of the mesh files in bytes",
    "max_collisions_per_link": "the largest number of collision shapes of a link",
}


def _split(item: Any) -> tuple[str, Any]:
    if isinstance(item, dict):
        return next(iter(item.items()))
    return item, None


def lower_test(section: TestSection, base_dir: Path, sink: Sink) -> TestPlan | None:
    """The TestPlan of a validated `test` section of a definition in `base_dir`."""
    lw = _TestLowering(section, base_dir, sink)
    errors = sink.error_count
    plan = TestPlan(span=section.span, tests=lw.tests(), tolerances=lw.tolerances(),
                    compare=lw.compare(), expected_mass=lw.expected_mass())
    return None if sink.error_count > errors else plan
