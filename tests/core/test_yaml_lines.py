"""Lines of a YAML file as editors count them (core/yaml_source.py: _Lines): PyYAML, reading
YAML 1.1, also breaks lines at U+0085, U+2028 and U+2029; a diagnostic's line and column, and
the line it quotes, are those of the file's \\n, \\r\\n and \\r lines, where editors show them."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpc.cli.main import main
from mpc.core import yaml_source
from mpc.core.diagnostics import Sink


def _check(capsys: pytest.CaptureFixture[str], path: Path, data: bytes) -> str:
    path.write_bytes(data)
    assert main(["check", str(path)]) == 1
    return capsys.readouterr().err


@pytest.mark.parametrize("brk", ["\u2028", "\u2029", "\x85"])
def test_a_malformed_definition_after_a_break_of_yaml_alone_is_quoted_on_its_own_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], brk: str) -> None:
    spec = tmp_path / "model.yml"
    text = f"# a comment{brk} and what PyYAML reads after it\nmodel:\n  robotname: r\n"
    err = _check(capsys, spec, text.encode())
    assert err == (f"{spec}:2:6: error[E0102]: malformed YAML: mapping values are not allowed here\n"
                   " 2 | model:\n"
                   "   |      ^\n"
                   "1 error in 1 file\n")


def test_a_value_after_a_line_separator_is_placed_on_the_file_s_line() -> None:
    text = "# one\u2028\nmodel:\n  robotname: r\u2028\n  modelname: m\n"
    doc = yaml_source.loads(text, "m.yml", Sink())
    assert doc is not None
    assert doc.data == {"model": {"robotname": "r", "modelname": "m"}}
    key, value = doc.keys[("model", "modelname")], doc.values[("model", "modelname")]
    assert (key.line, key.col, key.end_line, key.end_col) == (4, 3, 4, 12)
    assert (value.line, value.col, value.end_line, value.end_col) == (4, 14, 4, 15)
    # The line separator ends the scalar `r` for PyYAML; in the file it stands in line 3.
    robot = doc.values[("model", "robotname")]
    assert (robot.line, robot.col, robot.end_line, robot.end_col) == (3, 14, 3, 15)


def test_a_limit_past_a_line_separator_is_placed_on_the_file_s_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "model.yml"
    err = _check(capsys, spec, "# \u2028\nmodel:\n  x: &a [1, *a]\n".encode())
    assert f"{spec}:3:6: error[E0108]: a recursive alias: the value contains itself\n" in err


@pytest.mark.parametrize("brk", ["\r", "\r\n"])
def test_a_non_printable_character_is_placed_on_its_line_whatever_the_line_breaks(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], brk: str) -> None:
    spec = tmp_path / "model.yml"
    err = _check(capsys, spec, f"model:{brk}  robotname: a\x00b{brk}".encode())
    assert err.startswith(f"{spec}:2:15: error[E0107]: a non-printable character (#x0000) in YAML; "
                          "write it escaped in a double-quoted string\n")
