"""Span: where in which file something was written; 1-based line and column.

Every AST node, IR op and IR element read from a file carries one, so that an error
found at any stage points at the user's text.
"""

from __future__ import annotations

from typing import Any

from mpc.core.record import record


@record(slots=True)
class Span:
    """A region of a source file.

    file: the path as given (kept as the user wrote it, for messages).
    line, col: the first character, 1-based.
    end_line, end_col: one past the last character; equal to line/col when unknown.
    """

    file: str
    line: int = 1
    col: int = 1
    end_line: int = 0
    end_col: int = 0

    def __init__(self, file: str, line: int = 1, col: int = 1, end_line: int = 0,
                 end_col: int = 0) -> None:
        # Written here, not by dataclass (whose frozen __init__ sets each field through
        # object.__setattr__ and then calls __post_init__): the readers make a span for nearly
        # every element of a file, and the slots' own setters take half the time.
        if end_line < line or (end_line == line and end_col < col):
            end_line, end_col = line, col
        _set_file(self, file)
        _set_line(self, line)
        _set_col(self, col)
        _set_end_line(self, end_line)
        _set_end_col(self, end_col)

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"

    @classmethod
    def of_file(cls, file: str) -> Span:
        """The span of a whole file, for errors that concern the file itself."""
        return cls(file, 1, 1)


_set_file, _set_line, _set_col, _set_end_line, _set_end_col = (
    getattr(Span, name).__set__ for name in ("file", "line", "col", "end_line", "end_col"))


def hardened_parser(huge: bool = False) -> Any:
    """The one lxml parser of mpc (here, on the ground floor, for readers and IR alike): no
    DTD, no entity expansion, no network; huge trees only when asked (meshes: DAE files
    hold long arrays). A new parser per call: lxml parsers must not be shared between threads."""
    from lxml import etree

    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=huge,
                           remove_blank_text=False)
