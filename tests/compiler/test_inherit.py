"""Definition inheritance: `defaults` chains, the merge rule, spans across files, `@key@` substitution."""

from __future__ import annotations

from pathlib import Path

import git

from mpc.compiler.inherit import resolve
from mpc.core import yaml_source as source
from mpc.core.span import Span
from mpc.core.yaml_source import Document
from tests.conftest import Diags, write


def _resolve(path: Path, diags: Diags) -> Document | None:
    doc = source.load(path, diags)
    assert doc is not None
    return resolve(doc, path, diags)


def _paths(value: object, path: tuple = ()) -> list[tuple]:
    """Every path in `value`, itself included."""
    if isinstance(value, dict):
        return [path, *(p for k, v in value.items() for p in _paths(v, (*path, k)))]
    if isinstance(value, list):
        return [path, *(p for i, v in enumerate(value) for p in _paths(v, (*path, i)))]
    return [path]


def _chain(tmp_path: Path) -> Path:
    write(tmp_path / "base.yml", """
        default_model:
          robotname: base-bot
          version: "1.0"
          test:
            tolerances: {default: 0.01, mass: 0.01}
            tests: [compare_amount_joints]
          export_config:
            - type: urdf
        """)
    write(tmp_path / "mid.yml", """
        defaults: base.yml
        default_model:
          version: "2.0"
          test:
            tolerances: {mass: 0.05}
            tests: [compare_link_masses]
        """)
    return write(tmp_path / "robot.yml", """
        defaults: mid.yml
        model:
          robotname: arm
          test:
            tolerances: {rad: 0.1}
            tests: [topological_self_consistency]
          export_config:
            - type: sdf
        """)


def test_chain_merges_mappings_deeply_appends_lists_and_overrides_scalars(tmp_path: Path, diags: Diags):
    doc = _resolve(_chain(tmp_path), diags)
    assert doc is not None
    assert doc.data == {"model": {
        "robotname": "arm",
        "version": "2.0",
        "test": {"tolerances": {"default": 0.01, "mass": 0.05, "rad": 0.1},
                 "tests": ["compare_amount_joints", "compare_link_masses", "topological_self_consistency"]},
        "export_config": [{"type": "urdf"}, {"type": "sdf"}],
    }}
    assert doc.file == str(tmp_path / "robot.yml")


def test_spans_point_into_the_file_and_line_that_wrote_the_value(tmp_path: Path, diags: Diags):
    path = _chain(tmp_path)
    doc = _resolve(path, diags)
    assert doc is not None
    base, mid, robot = str(tmp_path / "base.yml"), str(tmp_path / "mid.yml"), str(path)
    # from the deepest defaults file
    assert doc.values[("model", "test", "tolerances", "default")] == Span(base, 5, 27, 5, 31)
    assert doc.keys[("model", "test", "tolerances", "default")] == Span(base, 5, 18, 5, 25)
    # a key written in both files is attributed to the nearer one
    assert doc.keys[("model", "export_config")] == Span(robot, 7, 3, 7, 16)
    # from the middle file and from the definition
    assert doc.values[("model", "version")] == Span(mid, 3, 12, 3, 17)
    assert doc.values[("model", "robotname")] == Span(robot, 3, 14, 3, 17)
    assert doc.keys[("model", "robotname")] == Span(robot, 3, 3, 3, 12)
    # list items after concatenation keep their own file and line
    assert doc.values[("model", "test", "tests", 0)] == Span(base, 6, 13, 6, 34)
    assert doc.values[("model", "test", "tests", 1)] == Span(mid, 6, 13, 6, 32)
    assert doc.values[("model", "test", "tests", 2)] == Span(robot, 6, 13, 6, 41)
    assert doc.values[("model", "export_config", 1, "type")] == Span(robot, 8, 13, 8, 16)
    assert doc.values[("model", "export_config", 0, "type")].file == base
    # every path of the merged data has a value span, and the tables have nothing else
    assert set(doc.values) == set(_paths(doc.data))
    assert set(doc.keys) == {p for p in _paths(doc.data) if p and isinstance(p[-1], str)}


def test_null_and_type_mismatch_replace_and_drop_inherited_spans(tmp_path: Path, diags: Diags):
    write(tmp_path / "base.yml", """
        default_model:
          frames: {a: 1, b: 2}
          mass: 3
        """)
    path = write(tmp_path / "robot.yml", """
        defaults: base.yml
        model:
          frames: [x]
          mass: null
        """)
    doc = _resolve(path, diags)
    assert doc is not None
    assert doc.data == {"model": {"frames": ["x"], "mass": None}}
    assert set(doc.values) == set(_paths(doc.data))
    assert doc.values[("model", "frames", 0)] == Span(str(path), 3, 12, 3, 13)


def test_substitution_keeps_type_and_interpolates_in_longer_strings(tmp_path: Path, diags: Diags):
    write(tmp_path / "base.yml", """
        default_model:
          modelname: "@robotname@-model"
          scale: 0.5
          links: [a, b]
        """)
    path = write(tmp_path / "robot.yml", """
        defaults: base.yml
        model:
          robotname: arm
          mass: "@scale@"
          keep: "@links@"
          note: "scale @scale@, count @count@, arm @robotname@"
          count: 3
          flag: "@count@"
          mail: a@example.com
        """)
    doc = _resolve(path, diags)
    assert doc is not None
    model = doc.data["model"]
    assert model["modelname"] == "arm-model"
    assert model["mass"] == 0.5 and isinstance(model["mass"], float)
    assert model["keep"] == ["a", "b"]
    assert model["flag"] == 3
    assert model["note"] == "scale 0.5, count 3, arm arm"
    assert model["mail"] == "a@example.com"
    # the substituted list sits where `@links@` was written; its items where they were
    assert doc.values[("model", "keep")] == Span(str(path), 5, 9, 5, 18)
    assert doc.values[("model", "keep", 1)] == Span(str(tmp_path / "base.yml"), 4, 14, 4, 15)
    assert set(doc.values) == set(_paths(doc.data))
    # the list is a copy, not shared with `links`
    assert model["keep"] is not model["links"]


def test_substitution_is_not_recursive_and_runs_without_defaults(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", """
        model:
          robotname: "@modelname@"
          modelname: "@robotname@"
        """)
    doc = _resolve(path, diags)
    assert doc is not None
    assert doc.data == {"model": {"robotname": "@robotname@", "modelname": "@modelname@"}}


def test_file_without_defaults_or_substitution_comes_back_equal(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", """
        model:
          robotname: arm
          export_config: [{type: urdf}]
        """)
    doc = source.load(path, diags)
    assert doc is not None
    out = resolve(doc, path, diags)
    assert out is not None and out.data == doc.data and out.values == doc.values


def test_unknown_substitution_with_did_you_mean(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", """
        model:
          robotname: arm
          modelname: "@robotnme@"
        """)
    assert _resolve(path, diags) is None
    d = diags.take_error("E0221")
    assert d.message == "unknown substitution '@robotnme@'; did you mean '@robotname@'?"
    assert d.span == Span(str(path), 3, 14, 3, 26)


def test_list_inside_a_longer_string_is_an_error(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", """
        model:
          links: [a]
          name: "x-@links@"
        """)
    assert _resolve(path, diags) is None
    d = diags.take_error("E0222")
    assert d.message == "substitution '@links@' is a list and cannot be part of a longer string"
    assert (d.span.line, d.span.col) == (3, 9)


def test_missing_defaults_file(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", """
        defaults: nowhere.yml
        model: {robotname: arm}
        """)
    assert _resolve(path, diags) is None
    d = diags.take_error("E0601")
    assert d.message == "defaults file 'nowhere.yml' does not exist"
    assert d.span == Span(str(path), 1, 11, 1, 22)


def test_three_file_cycle(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", "defaults: a.yml\nmodel: {robotname: arm}\n")
    write(tmp_path / "a.yml", "defaults: b.yml\ndefault_model: {}\n")
    write(tmp_path / "b.yml", "defaults: c.yml\ndefault_model: {}\n")
    write(tmp_path / "c.yml", "default_model: {}\ndefaults: a.yml\n")
    assert _resolve(path, diags) is None
    d = diags.take_error("E0220")
    assert d.message == "defaults cycle: a.yml → b.yml → c.yml → a.yml"
    assert d.span == Span(str(tmp_path / "c.yml"), 2, 11, 2, 16)


def test_self_cycle(tmp_path: Path, diags: Diags):
    path = write(tmp_path / "robot.yml", "defaults: robot.yml\nmodel: {robotname: arm}\n")
    assert _resolve(path, diags) is None
    d = diags.take_error("E0220")
    assert d.message == "defaults cycle: robot.yml → robot.yml"
    assert d.span == Span(str(path), 1, 11, 1, 20)


def test_paths_are_relative_to_the_naming_file(tmp_path: Path, diags: Diags):
    git.Repo.init(tmp_path)  # the project: defaults files lie in the definition's git work tree
    write(tmp_path / "base.yml", "default_model:\n  mass: 1\n  links: [base]\n")
    write(tmp_path / "defs" / "arm.yml", "defaults: ../base.yml\ndefault_model:\n  links: [arm]\n")
    path = write(tmp_path / "robots" / "robot.yml", "defaults: ../defs/arm.yml\nmodel:\n  links: [hand]\n")
    doc = _resolve(path, diags)
    assert doc is not None
    assert doc.data == {"model": {"mass": 1, "links": ["base", "arm", "hand"]}}
    assert doc.values[("model", "mass")] == Span(str(tmp_path / "base.yml"), 2, 9, 2, 10)
    assert doc.values[("model", "links", 1)].file == str(tmp_path / "defs" / "arm.yml")


def test_defaults_file_with_unknown_key(tmp_path: Path, diags: Diags):
    base = write(tmp_path / "base.yml", "default_model: {mass: 1}\ndefault: other.yml\n")
    path = write(tmp_path / "robot.yml", "defaults: base.yml\nmodel: {robotname: arm}\n")
    assert _resolve(path, diags) is None
    d = diags.take_error("E0201")
    assert d.message == "unknown key 'default' in a defaults file; did you mean 'defaults'?"
    assert d.span == Span(str(base), 2, 1, 2, 8)


def test_wrong_types(tmp_path: Path, diags: Diags):
    write(tmp_path / "base.yml", "defaults: [a.yml]\n")
    path = write(tmp_path / "robot.yml", "defaults: base.yml\nmodel: {robotname: arm}\n")
    assert _resolve(path, diags) is None
    assert "no 'default_model'" in diags.take_error("E0203").message
    d = diags.take_error("E0203")
    assert d.message.startswith("'defaults' must be the path of a defaults file")
    assert (d.span.file, d.span.line, d.span.col) == (str(tmp_path / "base.yml"), 1, 11)
