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

    def __post_init__(self) -> None:
        if self.end_line < self.line or (self.end_line == self.line and self.end_col < self.col):
            object.__setattr__(self, "end_line", self.line)
            object.__setattr__(self, "end_col", self.col)

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"

    @classmethod
    def of_file(cls, file: str) -> Span:
        """The span of a whole file, for errors that concern the file itself."""
        return cls(file, 1, 1)


def hardened_parser(huge: bool = False) -> Any:
    """The one lxml parser of mpc (here, on the ground floor, for readers and IR alike): no
    DTD, no entity expansion, no network; huge trees only when asked (meshes: DAE files
    hold long arrays). A new parser per call: lxml parsers must not be shared between threads."""
    from lxml import etree

    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=huge,
                           remove_blank_text=False)
