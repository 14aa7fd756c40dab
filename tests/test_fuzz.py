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


XACRO_PAYLOADS = [i for i, token in enumerate(TOKENS) if token.startswith(("${", "$(", "<xacro:"))]


@pytest.mark.parametrize("token", XACRO_PAYLOADS, ids=lambda i: TOKENS[i][:40])
def test_each_xacro_payload_is_refused_wherever_it_is_written(
        seeds: Seeds, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, token: int) -> None:
    """Issue 35: each xacro payload of TOKENS, as a link's name, as an include's filename and
    as an element of its own, fails the check and the build (exit 1) with the invariants of
    run_case: no code ran (no escape file), no secret in a message or an output."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    base = tmp_path / "a/b/cases"
    base.mkdir(parents=True)
    text = seeds.files["arm.urdf.xacro"].decode()
    places = (('<link name="base"', "value"), ("<xacro:include", "value"), ("  <xacro:include", "insert"))
    for anchor, op in places:
        edit = Edit(op, text.index(anchor) / len(text), token)
        for command in ("check", "compile"):
            assert run_case(seeds, base, "xacro", [edit], command) == 1, (anchor, op, command)
