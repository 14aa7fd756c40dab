"""A bounded fuzz run in CI (issues 17 and 29): mutated definitions, pipeline files, URDF,
SDF and SMURF inputs, STL, OBJ and DAE meshes, symbolic link loops and extreme inertias never
make mpc fail with a traceback (exit 3), nor write outside `-o`; and every file an accepted
run wrote is well-formed, holds finite numbers, and (URDF, SDF) loads in check_urdf and
`ign sdf -k`. The long run is bench/fuzz.py; the engine is tests/fuzzing.py."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzzing import KINDS, OPS, TOKENS, Edit, Outputs, Seeds, copy_problem, output_problem, run_case

EDITS = st.lists(st.builds(Edit, st.sampled_from(OPS), st.floats(0, 1), st.integers(0, len(TOKENS) - 1)),
                 min_size=1, max_size=3)


@pytest.fixture(scope="module")
def seeds(tmp_path_factory: pytest.TempPathFactory) -> Seeds:
    return Seeds.make(tmp_path_factory.mktemp("seeds"))


@pytest.mark.parametrize("kind", KINDS)
def test_mutated_inputs_exit_0_or_1_and_write_only_sound_files_into_the_output(
        seeds: Seeds, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))  # run_case sets it per case
    base = tmp_path / "a/b/cases"
    base.mkdir(parents=True)
    command = "check" if kind == "pipeline" else "compile"
    outputs = Outputs(tmp_path / "kept", sdf_every=10)

    @settings(max_examples=25, deadline=None, derandomize=True, database=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
    @given(EDITS)
    def one(edits: list[Edit]) -> None:
        run_case(seeds, base, kind, edits, command, outputs)

    one()
    assert outputs.invalid == []
    assert outputs.consumers_refuse() == []


@pytest.mark.parametrize(("name", "text", "problem"), [
    ("a.urdf", '<robot name="r" {http://example.com/ns}attr="v"/>', "not well-formed XML"),
    ("a.urdf", '<robot name="r" x:attr="v"/>', "not well-formed XML: unbound prefix"),
    ("a.urdf", '<robot name="r"><link name="inf"><mass value="nan"/></link></robot>',
     "a number that is not finite: 'nan'"),
    ("a.sdf", "<sdf><pose>0 0 inf 0 0 0</pose></sdf>", "a number that is not finite: '0 0 inf 0 0 0'"),
    ("a.yml", "a: [1, .inf]\n", "a number that is not finite: inf"),
])
def test_the_output_checks_refuse_what_consumers_refuse(tmp_path: Path, name: str, text: str,
                                                         problem: str) -> None:
    """The fuzz's own judge: it must see each class of invalid output of issue 29."""
    path = tmp_path / name
    path.write_text(text)
    assert (output_problem(path) or "").startswith(problem)


def test_the_output_checks_accept_names_that_read_as_numbers(tmp_path: Path) -> None:
    path = tmp_path / "a.urdf"
    path.write_text('<robot name="nan"><link name="inf"/></robot>')
    assert output_problem(path) is None


def test_a_mesh_copied_as_it_is_is_judged_by_the_reader_that_read_it(tmp_path: Path) -> None:
    """XML 1.0's fifth edition allows a U+FEFF in a name; expat, the judge of the XML mpc
    writes itself, keeps the older rules. A user's DAE copied as it is is judged by libxml2,
    which read it (and tinyxml2, Gazebo's reader, takes it too); what no reader takes is still
    refused."""
    path = tmp_path / "m.dae"
    path.write_text('<COLLADA x\ufeffy="1"/>', encoding="utf-8")
    assert (output_problem(path) or "").startswith("not well-formed XML")
    assert copy_problem(path) is None
    path.write_text('<COLLADA x<y="1"/>')
    assert (copy_problem(path) or "").startswith("not well-formed XML")


def test_a_dae_with_a_fifth_edition_name_is_copied_and_judged_as_the_users(
        seeds: Seeds, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """bench/fuzz.py's seed 1145: a U+FEFF inserted into an attribute's name of the DAE, which
    the SDF export copies as it is. The build succeeds and its outputs pass the judge."""
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    base = tmp_path / "a/b/cases"
    base.mkdir(parents=True)
    outputs = Outputs(tmp_path / "kept", sdf_every=1)
    assert run_case(seeds, base, "dae", [Edit("insert", 0.8971745659701676, 35)], "compile", outputs) == 0
    assert outputs.invalid == []
    assert outputs.consumers_refuse() == []


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
