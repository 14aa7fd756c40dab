"""The order `mpc run` starts models in (pipeline/schedule.py): the longest remaining path
first, weighted by last build times; models that share a basefile apart."""

from __future__ import annotations

from pathlib import Path

from mpc.pipeline import schedule

# a (10 s) alone; b (1 s) unblocks three 1-s models: b has more dependants, a the longer path.
PARENTS = {"b": [], "c": ["b"], "d": ["b"], "e": ["b"], "a": []}
SECONDS = {"a": 10.0, "b": 1.0, "c": 1.0, "d": 1.0, "e": 1.0}


def test_the_longest_remaining_path_starts_first_not_the_most_dependants() -> None:
    priority = schedule.priorities(PARENTS, SECONDS)
    assert priority == {"a": 10.0, "b": 2.0, "c": 1.0, "d": 1.0, "e": 1.0}
    assert schedule.next_model(["b", "a"], priority, [], {}) == "a"


def test_a_chain_of_short_models_outweighs_one_longer_model() -> None:
    parents = {"x": [], "y": ["x"], "z": ["y"], "long": []}
    priority = schedule.priorities(parents, {"x": 2.0, "y": 2.0, "z": 2.0, "long": 5.0})
    assert priority == {"x": 6.0, "y": 4.0, "z": 2.0, "long": 5.0}
    assert schedule.next_model(["long", "x"], priority, [], {}) == "x"


def test_models_never_built_count_the_median_of_the_known_times() -> None:
    assert schedule.expected_seconds(["a", "b", "c", "d"], {"a": 1.0, "b": 3.0, "c": 8.0}) == {
        "a": 1.0, "b": 3.0, "c": 8.0, "d": 3.0}
    assert schedule.expected_seconds(["a"], {}) == {"a": schedule.UNKNOWN_SECONDS}


def test_the_last_wall_time_wins_over_the_stage_times_of_the_state() -> None:
    status = {"models": {"a": {"seconds": 4.5}, "b": {"stages": {}}, "c": {"seconds": True}}}
    states = {"a": {"stages": {"compile": {"seconds": 2.0}}},
              "b": {"stages": {"compile": {"seconds": 1.25}, "test": {"seconds": 0.5}}},
              "d": {}}
    assert schedule.last_seconds(status, states) == {"a": 4.5, "b": 1.75}


def test_a_ready_model_sharing_no_basefile_with_a_running_one_goes_first(tmp_path: Path) -> None:
    priority = {"copy2": 3.0, "other": 2.0, "copy3": 1.0}
    source = {"copy1": frozenset({"ur5.urdf"}), "copy2": frozenset({"ur5.urdf"}),
              "copy3": frozenset({"ur5.urdf"}), "other": frozenset({"solo.urdf"})}
    running = [source["copy1"]]
    assert schedule.next_model(["copy2", "other", "copy3"], priority, running, source) == "other"
    # when every ready model shares one, the worker is not left idle: the highest priority starts
    assert schedule.next_model(["copy3", "copy2"], priority, running, source) == "copy2"


def test_sources_are_the_basefiles_resolved_from_the_definition(tmp_path: Path) -> None:
    data = {"model": {"input_models": {
        "a": {"basefile": "robots/a.urdf"}, "b": {"basefile": "package://pkg/b.urdf"},
        "c": {"derived_base": "c.yml"}, "d": "not a mapping"}}}
    assert schedule.sources(tmp_path / "m.yml", data) == {str(tmp_path / "robots" / "a.urdf"),
                                                          "package://pkg/b.urdf"}
    assert schedule.sources(tmp_path / "m.yml", None) == frozenset()
