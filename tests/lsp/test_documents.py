"""lsp/documents.py: the buffers as incremental changes leave them (LSP ranges: lines from 0,
characters in UTF-16 code units, any of the three line breaks), and the files URIs name."""

from __future__ import annotations

from pathlib import Path

from mpc.lsp.documents import Documents, offset, path_of


def at(line: int, character: int) -> dict[str, int]:
    return {"line": line, "character": character}


def change(start: tuple[int, int], end: tuple[int, int], text: str) -> dict:
    return {"range": {"start": at(*start), "end": at(*end)}, "text": text}


def test_offsets_count_utf16_units_and_every_line_break() -> None:
    text = "a😀b\r\nc\rd\ne"
    assert offset(text, at(0, 3)) == 2  # after the emoji: two units, one code point
    assert offset(text, at(1, 0)) == text.index("c")
    assert offset(text, at(2, 1)) == text.index("d") + 1
    assert offset(text, at(3, 0)) == text.index("e")


def test_offsets_past_a_lines_end_or_the_last_line() -> None:
    text = "ab\ncd"
    assert offset(text, at(0, 99)) == 2  # the line's end, not into the next line
    assert offset(text, at(7, 0)) == len(text)


def test_incremental_changes_apply_in_order() -> None:
    documents = Documents()
    uri = "file:///w/a.yml"
    documents.opened(uri, "joints:\n  elbo:\n    damping: 1\n", 1)
    assert documents.changed(uri, 2, [change((1, 6), (1, 6), "w"),  # elbo → elbow
                                      change((2, 13), (2, 14), "0.5"),  # 1 → 0.5
                                      {"text": "model:\n"}, change((1, 0), (1, 0), "  x: 1\n")])
    assert documents.open[uri].text == "model:\n  x: 1\n"
    assert documents.open[uri].version == 2
    documents.opened(uri, "a: 😀x\n", 3)
    documents.changed(uri, 4, [change((0, 3), (0, 5), "")])  # the emoji's two units
    assert documents.open[uri].text == "a: x\n"


def test_a_change_to_a_buffer_that_is_not_open() -> None:
    documents = Documents()
    assert documents.changed("file:///w/b.yml", 2, [{"text": "x"}]) is False
    assert documents.open == {}


def test_the_files_of_uris() -> None:
    assert path_of("file:///home/u/my%20robot/a.yml") == Path("/home/u/my robot/a.yml")
    assert path_of("file://localhost/tmp/a.yml") == Path("/tmp/a.yml")
    assert path_of("untitled:Untitled-1") == Path("untitled:Untitled-1")
