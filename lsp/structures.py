"""The LSP structures the server sends and reads, as the JSON objects they are on the wire.

TypedDicts: at run time plain dicts that `json.dumps` writes as they are (no converter, no
classes per message), for the type checker the shapes of the LSP specification (3.17). Optional
fields are left out rather than set to null, as LSP clients expect. Only what mpc's server uses
is here; the kinds are the specification's numbers.
"""

from __future__ import annotations

from typing import Final, NotRequired, TypedDict


class Position(TypedDict):
    line: int  # from 0
    character: int  # from 0, in UTF-16 code units


class Range(TypedDict):
    start: Position
    end: Position


class Location(TypedDict):
    uri: str
    range: Range


class DiagnosticRelatedInformation(TypedDict):
    location: Location
    message: str


class Diagnostic(TypedDict):
    range: Range
    message: str
    severity: NotRequired[int]
    code: NotRequired[str]
    source: NotRequired[str]
    relatedInformation: NotRequired[list[DiagnosticRelatedInformation]]


class MarkupContent(TypedDict):
    kind: str
    value: str


class TextEdit(TypedDict):
    range: Range
    newText: str


class CompletionItem(TypedDict):
    label: str
    kind: NotRequired[int]
    detail: NotRequired[str]
    documentation: NotRequired[MarkupContent]
    textEdit: NotRequired[TextEdit]


class CompletionList(TypedDict):
    isIncomplete: bool
    items: list[CompletionItem]


class Hover(TypedDict):
    contents: MarkupContent
    range: NotRequired[Range]


class DocumentSymbol(TypedDict):
    name: str
    kind: int
    range: Range
    selectionRange: Range
    children: NotRequired[list[DocumentSymbol]]


class WorkspaceEdit(TypedDict):
    changes: dict[str, list[TextEdit]]


class CodeAction(TypedDict):
    title: str
    kind: str
    diagnostics: list[Diagnostic]
    isPreferred: bool
    edit: WorkspaceEdit


MARKDOWN: Final = "markdown"
QUICK_FIX: Final = "quickfix"


class Severity:
    """DiagnosticSeverity."""

    ERROR: Final = 1
    WARNING: Final = 2
    INFORMATION: Final = 3


class ItemKind:
    """CompletionItemKind."""

    VALUE: Final = 12
    CLASS: Final = 7
    INTERFACE: Final = 8
    PROPERTY: Final = 10
    COLOR: Final = 16
    FILE: Final = 17
    FOLDER: Final = 19
    ENUM_MEMBER: Final = 20


class SymbolKind:
    NAMESPACE: Final = 3
    FIELD: Final = 8
