"""What a run where all is cached skips, and what it must still notice: a pipeline file the
schema accepted is remembered (pipeline/verdicts.py), mpc's version is read without
importlib.metadata (core/version.py), and mpc's sources are known by their status
(core/version.py). Each remembered answer is given again only for the same input."""

from __future__ import annotations

import os
import sys
import time
from importlib import metadata
from pathlib import Path

import pytest

from mpc.core import version, yaml_source
from mpc.core.diagnostics import Sink
from mpc.core.version import mpc_version as installed_version
from mpc.pipeline.plan import load_plan
from mpc.pipeline.verdicts import valid_pipeline
from tests.conftest import write

GOOD = "pipeline:\n  root: .\n  model_definitions: [a.yml]\n  central_meshes: false\n"


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _verdict(path: Path) -> tuple[bool, list[str]]:
    sink = Sink()
    doc = yaml_source.load(path, sink)
    assert doc is not None
    return valid_pipeline(doc, sink), [f"{d.span.line}:{d.span.col} {d.code} {d.message}" for d in sink]


def test_an_accepted_pipeline_file_is_remembered_and_its_plan_keeps_the_validated_settings(
        tmp_path: Path, cache: Path) -> None:
    pipeline = write(tmp_path / "pipeline.yml", GOOD)
    assert _verdict(pipeline) == (True, [])
    assert len(list((cache / "verdicts").glob("*"))) == 1
    assert _verdict(pipeline) == (True, [])
    plan = load_plan(pipeline, Sink())  # from the remembered verdict: the settings are validated on demand
    assert plan is not None and plan.section is not None
    assert plan.section.central_meshes is False and plan.section.model_definitions == ["a.yml"]


def test_an_edit_of_a_remembered_pipeline_file_is_validated_again(tmp_path: Path, cache: Path) -> None:
    pipeline = write(tmp_path / "pipeline.yml", GOOD)
    assert _verdict(pipeline) == (True, [])
    pipeline.write_text(GOOD.replace("central_meshes", "central_meshs"))  # same size
    expected = "4:3 E0201 unknown key 'central_meshs' in pipeline; did you mean 'central_meshes'?"
    assert _verdict(pipeline) == (False, [expected])
    assert _verdict(pipeline) == (False, [expected])  # a refused file is never remembered
    assert len(list((cache / "verdicts").glob("*"))) == 1


def test_a_verdict_of_another_mpc_is_not_used(tmp_path: Path, cache: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    pipeline = write(tmp_path / "pipeline.yml", GOOD)
    assert _verdict(pipeline) == (True, [])
    monkeypatch.setattr("mpc.pipeline.verdicts.source_version", lambda: "0.0.0+another")
    assert _verdict(pipeline) == (True, [])
    assert len(list((cache / "verdicts").glob("*"))) == 2


def test_an_unwritable_cache_costs_only_validating(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write(tmp_path / "cache", "a file where the cache folder should be\n")
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    pipeline = write(tmp_path / "pipeline.yml", GOOD)
    assert _verdict(pipeline) == (True, [])
    assert _verdict(pipeline) == (True, [])


def test_the_version_is_the_installed_distributions(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert installed_version() == metadata.version("model-pipeline-compiler")
    info = tmp_path / "site" / "model_pipeline_compiler-9.8.7.dist-info"
    write(info / "METADATA", "Metadata-Version: 2.1\nName: model-pipeline-compiler\nVersion: 9.8.7\n")
    monkeypatch.setattr(sys, "path", [str(tmp_path / "site"), *sys.path])
    assert installed_version() == "9.8.7"  # the first one on sys.path, as Python imports it


def test_an_edit_of_mpcs_sources_is_noticed_with_the_same_size_and_time(
        tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    source = write(tmp_path / "compiler" / "lower.py", "x = 1\n")
    monkeypatch.setattr(version, "_source_stats",
                        lambda: [("compiler/lower.py", source, os.stat(source))])
    version.source_version.cache_clear()
    try:
        before = version.source_version()
        assert version.source_version.__wrapped__() == before  # known again from the status alone
        st = os.stat(source)
        while time.time_ns() < st.st_ctime_ns + 20_000_000:  # file times tick coarsely: let one pass
            time.sleep(0.005)
        source.write_text("x = 2\n")
        os.utime(source, ns=(st.st_atime_ns, st.st_mtime_ns))
        assert os.stat(source).st_size == st.st_size and os.stat(source).st_mtime_ns == st.st_mtime_ns
        assert version.source_version.__wrapped__() != before
    finally:
        version.source_version.cache_clear()
