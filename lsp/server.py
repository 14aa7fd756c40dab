"""The language server: LSP over stdio (lsp/endpoint.py, mpc's own JSON-RPC) → analyses of the
open buffers → diagnostics and the editor features of completion.py, hover.py and navigation.py.

A change is checked after a short quiet time (debounce; `mpc lsp --debounce-ms`, default 5 ms),
so that a burst of keystrokes is checked once; a request (completion, hover…) checks a pending
change first, so it always sees the buffer as it is. After a file is checked, the open files
whose check read it (as their `defaults` chain, as a derived_base parent) are checked again.
Input models stay in one ModelCache (bounded; their spans found as they enter, so no parse
stays alive), re-read only when their file changes.
"""

from __future__ import annotations

import gc
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mpc.compiler.options import ModelCache, Options
from mpc.core.cycles import paused_cycle_collection
from mpc.core.heap import give_back
from mpc.core.packages import PackageResolver
from mpc.core.version import mpc_version
from mpc.lsp import completion, hover, navigation
from mpc.lsp import structures as lsp
from mpc.lsp.analysis import Analysis, analyse
from mpc.lsp.diagnostics import convert
from mpc.lsp.documents import Documents, path_of
from mpc.lsp.endpoint import Endpoint, RequestError
from mpc.lsp.protocol import INVALID_PARAMS
from mpc.lsp.text import Lines
from mpc.lsp.transport import Inbox, Outbox, protocol_streams

CAPABILITIES = {
    "positionEncoding": "utf-16",
    "textDocumentSync": {"openClose": True, "change": 2, "save": True},  # 2: incremental
    "completionProvider": {"triggerCharacters": [":", " ", "/", "-", "["]},
    "hoverProvider": True,
    "definitionProvider": True,
    "documentSymbolProvider": True,
    "codeActionProvider": {"codeActionKinds": [lsp.QUICK_FIX]},
    "renameProvider": True,
}


class MpcServer(Endpoint):
    """The open buffers, their analyses and what is waiting to be checked."""

    def __init__(self, packages: dict[str, Path] | None = None,
                 write: Callable[[bytes], None] = lambda data: None) -> None:
        super().__init__(write, "mpc", mpc_version())
        resolver = PackageResolver(package_map=dict(packages or {}))
        self.options = Options(resolver=resolver, models=ModelCache())
        self.documents = Documents()
        self.analyses: dict[str, Analysis] = {}
        self.named: dict[str, Analysis] = {}  # the last analysis of each buffer that got a program
        self.debounce = 0.005
        self.capabilities = CAPABILITIES
        self.notifications.update({
            "textDocument/didOpen": self.did_open, "textDocument/didChange": self.did_change,
            "textDocument/didSave": self.did_save, "textDocument/didClose": self.did_close})
        self.requests.update({
            "textDocument/completion": self.complete, "textDocument/hover": self.hover,
            "textDocument/definition": self.definition, "textDocument/documentSymbol": self.symbols,
            "textDocument/rename": self.rename, "textDocument/codeAction": self.code_actions})

    def check(self, uri: str, dependents: bool = True) -> Analysis:
        """Check the buffer now and publish its diagnostics (then those of the files using it)."""
        self.cancel_timer(uri)
        document = self.documents.open[uri]
        path = path_of(uri)
        # A check allocates some hundred thousand objects and frees nearly all by reference
        # counting; the cyclic collector, run in between over all the server holds, took 20 of a
        # TALOS check's 50 ms. Its cycles are collected after the diagnostics have gone out.
        with paused_cycle_collection():
            analysis = analyse(path, document.text, self.documents.texts(), self.options)
            diagnostics = convert(analysis.diagnostics, path, Lines(analysis.text), analysis.readers())
            self.notify("textDocument/publishDiagnostics",
                        {"uri": uri, "diagnostics": diagnostics, "version": document.version})
        give_back()  # what the check freed outside Python's allocator (0.8 MiB of TALOS's)
        self.analyses[uri] = analysis
        if analysis.passed is not None:
            self.named[uri] = analysis
        if dependents:
            here = os.path.abspath(path)
            for other, known in list(self.analyses.items()):
                if other != uri and here in known.depends and other in self.documents.open:
                    self.check(other, dependents=False)
        return analysis

    def check_later(self, uri: str) -> None:
        """Check the buffer once it has been quiet for the debounce time."""
        self.later(uri, self.debounce, lambda: self.check(uri))

    def current(self, params: dict[str, Any]) -> Analysis:
        """The analysis of the request's buffer as it is now (a pending change is checked first)."""
        uri = params["textDocument"]["uri"]
        if uri not in self.documents.open:
            raise RequestError(INVALID_PARAMS, f"{uri} is not open (textDocument/didOpen)")
        if uri in self.timers or uri not in self.analyses:
            return self.check(uri)
        return self.analyses[uri]

    # notifications

    def did_open(self, params: dict[str, Any]) -> None:
        document = params["textDocument"]
        self.documents.opened(document["uri"], document["text"], document["version"])
        self.check(document["uri"])

    def did_change(self, params: dict[str, Any]) -> None:
        uri = params["textDocument"]["uri"]
        if self.documents.changed(uri, params["textDocument"]["version"], params["contentChanges"]):
            self.check_later(uri)

    def did_save(self, params: dict[str, Any]) -> None:
        uri = params["textDocument"]["uri"]
        if uri in self.documents.open:
            self.check_later(uri)

    def did_close(self, params: dict[str, Any]) -> None:
        uri = params["textDocument"]["uri"]
        self.cancel_timer(uri)
        self.documents.closed(uri)
        self.analyses.pop(uri, None)
        self.named.pop(uri, None)
        self.notify("textDocument/publishDiagnostics", {"uri": uri, "diagnostics": []})

    # requests

    def complete(self, params: dict[str, Any]) -> lsp.CompletionList:
        analysis = self.current(params)
        items = completion.complete(analysis, self.named.get(params["textDocument"]["uri"]),
                                    params["position"])
        return {"isIncomplete": False, "items": items}

    def hover(self, params: dict[str, Any]) -> lsp.Hover | None:
        return hover.hover(self.current(params), params["position"])

    def definition(self, params: dict[str, Any]) -> lsp.Location | None:
        return navigation.definition(self.current(params), params["position"])

    def symbols(self, params: dict[str, Any]) -> list[lsp.DocumentSymbol]:
        return navigation.symbols(self.current(params))

    def rename(self, params: dict[str, Any]) -> lsp.WorkspaceEdit | None:
        return navigation.rename(self.current(params), params["position"], params["newName"])

    def code_actions(self, params: dict[str, Any]) -> list[lsp.CodeAction]:
        return navigation.code_actions(params["textDocument"]["uri"], params["context"]["diagnostics"])


def serve(packages: dict[str, Path] | None = None, debounce_ms: float | None = None) -> int:
    """Run the server on stdin and stdout until the client says exit; the exit status (LSP: 0
    after shutdown, else 1)."""
    stdin, stdout = protocol_streams()
    ls = MpcServer(packages, Outbox(stdout).write)
    gc.freeze()  # mpc's modules and the schema live as long as the server: never scan them again
    if debounce_ms is not None:
        ls.debounce = debounce_ms / 1000
    return ls.run(Inbox(stdin))
