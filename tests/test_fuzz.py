"""A bounded fuzz run in CI (issue 17): mutated definitions, pipeline files, URDF, SDF and
SMURF inputs never make mpc fail with a traceback (exit 3), nor write outside `-o`.
The long run is bench/fuzz.py; the engine is tests/fuzzing.py."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzzing import KINDS, OPS, TOKENS, Edit, Seeds, run_case

EDITS = st.lists(st.builds(Edit, st.sampled_from(OPS), st.floats(0, 1), st.integers(0, len(TOKENS) - 1)),
                 min_size=1, max_size=3)


@pytest.fixture(scope="module")
def seeds(tmp_path_factory: pytest.TempPathFactory) -> Seeds:
    return Seeds.make(tmp_path_factory.mktemp("seeds"))


@pytest.mark.parametrize("kind", KINDS)
def test_mutated_inputs_exit_0_or_1_and_write_only_into_the_output(
        seeds: Seeds, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))  # run_case sets it per case
    base = tmp_path / "a/b/cases"
    base.mkdir(parents=True)
    command = "check" if kind == "pipeline" else "compile"

    @settings(max_examples=25, deadline=None, derandomize=True, database=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
    @given(EDITS)
    def one(edits: list[Edit]) -> None:
        run_case(seeds, base, kind, edits, command)

    one()
