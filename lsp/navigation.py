"""Go to definition (a link or joint into its model file's line; `derived_base`, `defaults` and
`basefile` into their file), document symbols, rename of a link or joint across the definition,
and code actions that apply a did-you-mean.

What this does not do: find what is under the cursor (lookup.py).
"""

from __future__ import annotations

from pathlib import Path

from mpc.core.span import Span
from mpc.lsp import structures as lsp
from mpc.lsp.analysis import Analysis
from mpc.lsp.diagnostics import DID_YOU_MEAN, location, uri_of
from mpc.lsp.lookup import element, target, written_at
from mpc.lsp.text import Lines

_FILE_KEYS = ("derived_base", "defaults", "basefile")


def definition(analysis: Analysis, position: lsp.Position) -> lsp.Location | None:
    lines = Lines(analysis.text)
    found = target(analysis, position["line"], lines.column(position))
    if found is None:
        return None
    if not found.on_key and found.key in _FILE_KEYS:
        return _file(analysis, found.key, found.word, found.span.line)
    if found.kinds:
        hit = element(analysis, found.word, found.kinds)
        span = written_at(analysis, hit[1]) if hit is not None else None
        if span is not None:
            return _location(span)
    return None


def _location(span: Span) -> lsp.Location:
    """The place of a span in a file on disk (a tag may span lines: the file's text is read)."""
    try:
        lines = Lines(Path(span.file).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError):
        return location(span)
    return lsp.Location(uri=uri_of(span.file), range=lines.range(span))


def _file(analysis: Analysis, key: str, written: str, line: int) -> lsp.Location | None:
    """The file a `derived_base`, `defaults` or `basefile` value (on 1-based `line`) names."""
    path: Path | None = (analysis.path.parent / written) if "://" not in written else None
    for inp in analysis.program.inputs.values() if analysis.program is not None else ():
        if inp.span.line == line and inp.path is not None:  # package:// paths, as the compiler found them
            path = inp.path
    if path is None or not path.is_file():
        return None
    start = lsp.Position(line=0, character=0)
    return lsp.Location(uri=uri_of(str(path)), range=lsp.Range(start=start, end=start))


def symbols(analysis: Analysis) -> list[lsp.DocumentSymbol]:
    """The keys of the buffer as a tree (sections, entries, their keys), three levels deep."""
    doc = analysis.doc
    if doc is None:
        return []
    lines = Lines(analysis.text)
    by_parent: dict[tuple, list[lsp.DocumentSymbol]] = {}
    for path in sorted(doc.keys, key=len, reverse=True):
        if len(path) > 4 or not all(isinstance(p, str) for p in path):
            continue
        key_span = doc.keys[path]
        value = doc.values.get(path, key_span)
        whole = Span(key_span.file, key_span.line, key_span.col, value.end_line, value.end_col)
        kind = lsp.SymbolKind.NAMESPACE if isinstance(doc.data_at(path), dict) else lsp.SymbolKind.FIELD
        symbol = lsp.DocumentSymbol(name=str(path[-1]), kind=kind, range=lines.range(whole),
                                    selectionRange=lines.range(key_span))
        children = by_parent.pop(path, None)
        if children:
            symbol["children"] = children
        by_parent.setdefault(path[:-1], []).insert(0, symbol)
    out = by_parent.get((), [])
    _sort(out)
    return out


def _sort(symbols: list[lsp.DocumentSymbol]) -> None:
    """In the order of the text, at every level."""
    symbols.sort(key=lambda s: (s["range"]["start"]["line"], s["range"]["start"]["character"]))
    for symbol in symbols:
        _sort(symbol.get("children", []))


def rename(analysis: Analysis, position: lsp.Position, new_name: str) -> lsp.WorkspaceEdit | None:
    """Every place of the definition that names the same link or joint, renamed."""
    lines = Lines(analysis.text)
    found = target(analysis, position["line"], lines.column(position))
    if found is None or not set(found.kinds) & {"link", "joint"}:
        return None
    edits = []
    for site in analysis.sites:
        if not set(site.kinds) & set(found.kinds) or site.span.line != site.span.end_line:
            continue
        written = lines.line(site.span.line - 1)[site.span.col - 1:site.span.end_col - 1]
        quote = written[:1] if written[:1] in "'\"" and written[-1:] == written[:1] else ""
        if written.strip("'\"") == found.word:
            edits.append(lsp.TextEdit(range=lines.range(site.span), newText=f"{quote}{new_name}{quote}"))
    if not any(e["range"] == lines.range(found.span) for e in edits):
        edits.append(lsp.TextEdit(range=lines.range(found.span), newText=new_name))
    return lsp.WorkspaceEdit(changes={uri_of(str(analysis.path)): edits})


def code_actions(uri: str, diagnostics: list[lsp.Diagnostic]) -> list[lsp.CodeAction]:
    """A quick fix for every diagnostic that says 'did you mean …?': write that instead."""
    out = []
    for d in diagnostics:
        match = DID_YOU_MEAN.search(d["message"])
        if match is None or d["range"]["start"]["line"] != d["range"]["end"]["line"]:
            continue
        fix = lsp.TextEdit(range=d["range"], newText=match.group(1))
        out.append(lsp.CodeAction(title=f"Change to '{match.group(1)}'", kind=lsp.QUICK_FIX,
                                  diagnostics=[d], isPreferred=True,
                                  edit=lsp.WorkspaceEdit(changes={uri: [fix]})))
    return out
