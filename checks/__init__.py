"""mpc.checks: model tests (the `test` section) on a compiled model → a protocol.

`run_model_tests(program, built, sink, workdir=…)` is the entry point; `Protocol` renders
the results as Markdown, JSON and JUnit XML. Pinocchio and PyBullet load only when a test
uses them.
"""

from __future__ import annotations

from mpc.checks.protocol import Protocol, Result
from mpc.checks.runner import run_model_tests

__all__ = ["Protocol", "Result", "run_model_tests"]
