"""Shared fixtures: the example-robot-data models, a compile helper, and `diags`.

`diags` records every diagnostic a test produces; the test takes the ones it
expects, and teardown fails on any it did not take (as Drake's test fixture does),
so no diagnostic goes unnoticed.
"""

from __future__ import annotations

import os
import tempfile
import textwrap
from pathlib import Path

import pytest
from hypothesis import settings

from mpc.compiler.driver import Options, Result, compile_model
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.packages import PackageResolver

# Property tests are bounded: a fixed number of examples and no per-example deadline (the
# machines are shared; a slow example is not a failure). `HYPOTHESIS_PROFILE=long` digs deeper.
settings.register_profile("bounded", max_examples=100, deadline=None)
settings.register_profile("long", max_examples=5000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "bounded"))

# The suite's tests already run side by side on every core: a build computes its meshes in
# this process (tests/backends/test_mesh_pool.py checks the pool of processes that a build
# uses alone; every build in a pytest worker would fork that big process to make one).
os.environ.setdefault("MPC_MESH_WORKERS", "1")
# mpc's cache is the suite's own (one per pytest process, shared by its tests), never the
# user's ~/.cache/mpc: what earlier versions of mpc kept there would show in the tests'
# diagnostics. A test that needs a cache of its own sets MPC_CACHE_DIR itself.
_CACHE = tempfile.TemporaryDirectory(prefix="mpc-test-cache-")
os.environ["MPC_CACHE_DIR"] = _CACHE.name


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The `long` tests first: the workers of `-n auto` take tests in this order, and a long
    test that starts last would leave one core idle until it ends."""
    items.sort(key=lambda item: item.get_closest_marker("long") is None)


ERD_PACKAGE = PackageResolver().find("example-robot-data")
assert ERD_PACKAGE is not None, "example-robot-data is not installed (bash scripts/setup.sh)"
ERD = ERD_PACKAGE / "robots"


class Diags(Sink):
    """A sink whose diagnostics a test must consume."""

    def take(self, code: str, severity: Severity = Severity.ERROR) -> Diagnostic:
        for i, d in enumerate(self.diagnostics):
            if d.code == code and d.severity is severity:
                return self.diagnostics.pop(i)
        raise AssertionError(f"no {severity.value} {code} among {self.summary()}")

    def take_error(self, code: str) -> Diagnostic:
        return self.take(code, Severity.ERROR)

    def summary(self) -> list[str]:
        return [f"{d.span}: {d.code}: {d.message}" for d in self.diagnostics]


@pytest.fixture
def diags() -> Diags:
    sink = Diags()
    yield sink
    assert not sink.diagnostics, f"diagnostics nobody took: {sink.summary()}"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text).lstrip("\n"))
    return path


def definition(basefile: str | Path, mesh_format: str = "input_type", robotname: str = "robot") -> str:
    return textwrap.dedent(f"""\
        model:
          robotname: {robotname}
          modelname: {robotname}-model
          input_models:
            base:
              basefile: "{basefile}"
          assemble:
            model: base
          export_config:
            - type: urdf
              mesh_format: {mesh_format}
        """)


def compile_file(path: Path, out: Path, sink: Sink) -> Result:
    return compile_model(path, sink, Options(out=out))
