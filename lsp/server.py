"""The language server: LSP over stdio (pygls) → analyses of the open buffers → diagnostics and
the editor features of completion.py, hover.py and navigation.py.

A change is checked after a short quiet time (debounce; `mpc lsp --debounce-ms`, default 5 ms),
so that a burst of keystrokes is checked once; a request (completion, hover…) checks a pending
change first, so it always sees the buffer as it is. After a file is checked, the open files
whose check read it (as their `defaults` chain, as a derived_base parent) are checked again.
Input models stay in one ModelCache (bounded; their spans found as they enter, so no parse
stays alive), re-read only when their file changes.
"""

from __future__ import annotations

import asyncio
import gc
import os
import sys
import threading
from pathlib import Path
from typing import BinaryIO

from lsprotocol import types as lsp
from pygls.server import LanguageServer, StdOutTransportAdapter
from pygls.uris import to_fs_path

from mpc.compiler.options import ModelCache, Options
from mpc.core.cycles import paused_cycle_collection
from mpc.core.packages import PackageResolver
from mpc.core.version import mpc_version
from mpc.lsp import completion, hover, navigation
from mpc.lsp.analysis import Analysis, analyse
from mpc.lsp.diagnostics import convert
from mpc.lsp.framing import FrameReader
from mpc.lsp.protocol import MpcProtocol
from mpc.lsp.text import Lines


class MpcServer(LanguageServer):
    """The open buffers' analyses and what is waiting to be checked."""

    def __init__(self, packages: dict[str, Path] | None = None) -> None:
        super().__init__("mpc", mpc_version(), protocol_cls=MpcProtocol)
        resolver = PackageResolver(package_map=dict(packages or {}))
        self.options = Options(resolver=resolver, models=ModelCache())
        self.analyses: dict[str, Analysis] = {}
        self.named: dict[str, Analysis] = {}  # the last analysis of each buffer that got a program
        self.pending: dict[str, asyncio.TimerHandle] = {}
        self.debounce = 0.005

    def start_io(self, stdin: BinaryIO | None = None, stdout: BinaryIO | None = None) -> None:
        """Serve the frames of stdin until the client says exit or stdin ends. pygls's own
        loop, with mpc's reader (lsp/framing.py) and protocol (lsp/protocol.py), which stay in
        step with the client whatever it sends."""
        rfile, wfile = stdin or sys.stdin.buffer, stdout or sys.stdout.buffer
        self._stop_event = threading.Event()
        self.lsp.connection_made(StdOutTransportAdapter(rfile, wfile))  # type: ignore[arg-type]
        try:
            self.loop.run_until_complete(self._serve_frames(FrameReader(rfile)))
        except BrokenPipeError:
            pass  # the client has gone
        except (KeyboardInterrupt, SystemExit):
            pass  # `exit` ends the server by SystemExit, as pygls does
        finally:
            self.shutdown()

    async def _serve_frames(self, reader: FrameReader) -> None:
        protocol = self.lsp
        assert isinstance(protocol, MpcProtocol) and self._stop_event is not None
        while not self._stop_event.is_set():
            frame = await self.loop.run_in_executor(self.thread_pool_executor, reader.next)
            if frame is None:
                return
            protocol.receive(frame)

    def path(self, uri: str) -> Path:
        return Path(to_fs_path(uri) or uri)

    def open_texts(self) -> dict[str, str]:
        return {os.path.abspath(self.path(uri)): doc.source
                for uri, doc in self.workspace.text_documents.items()}

    def check(self, uri: str, dependents: bool = True) -> Analysis:
        """Check the buffer now and publish its diagnostics (then those of the files using it)."""
        self.cancel(uri)
        document = self.workspace.get_text_document(uri)
        path = self.path(uri)
        # A check allocates some hundred thousand objects and frees nearly all by reference
        # counting; the cyclic collector, run in between over all the server holds, took 20 of a
        # TALOS check's 50 ms. Its cycles are collected after the diagnostics have gone out.
        with paused_cycle_collection():
            analysis = analyse(path, document.source, self.open_texts(), self.options)
        self.analyses[uri] = analysis
        if analysis.passed is not None:
            self.named[uri] = analysis
        diagnostics = convert(analysis.diagnostics, path, Lines(analysis.text), analysis.readers())
        self.publish_diagnostics(uri, diagnostics, version=document.version)
        if dependents:
            here = os.path.abspath(path)
            for other, known in list(self.analyses.items()):
                if other != uri and here in known.depends and other in self.workspace.text_documents:
                    self.check(other, dependents=False)
        return analysis

    def cancel(self, uri: str) -> None:
        """Forget the check waiting for the buffer's quiet time, if any."""
        handle = self.pending.pop(uri, None)
        if handle is not None:
            handle.cancel()

    def later(self, uri: str) -> None:
        """Check the buffer once it has been quiet for the debounce time."""
        self.cancel(uri)
        self.pending[uri] = asyncio.get_running_loop().call_later(self.debounce, self.check, uri)

    def current(self, uri: str) -> Analysis:
        """The analysis of the buffer as it is now (a pending change is checked first)."""
        if uri in self.pending or uri not in self.analyses:
            return self.check(uri)
        return self.analyses[uri]


def server(packages: dict[str, Path] | None = None) -> MpcServer:
    """The server with every feature registered."""
    ls = MpcServer(packages)

    @ls.feature(lsp.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls: MpcServer, params: lsp.DidOpenTextDocumentParams) -> None:
        ls.check(params.text_document.uri)

    @ls.feature(lsp.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(ls: MpcServer, params: lsp.DidChangeTextDocumentParams) -> None:
        ls.later(params.text_document.uri)

    @ls.feature(lsp.TEXT_DOCUMENT_DID_SAVE)
    def did_save(ls: MpcServer, params: lsp.DidSaveTextDocumentParams) -> None:
        ls.later(params.text_document.uri)

    @ls.feature(lsp.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(ls: MpcServer, params: lsp.DidCloseTextDocumentParams) -> None:
        uri = params.text_document.uri
        ls.cancel(uri)
        ls.analyses.pop(uri, None)
        ls.named.pop(uri, None)
        ls.publish_diagnostics(uri, [])

    @ls.feature(lsp.TEXT_DOCUMENT_COMPLETION,
                lsp.CompletionOptions(trigger_characters=[":", " ", "/", "-", "["]))
    def complete(ls: MpcServer, params: lsp.CompletionParams) -> lsp.CompletionList:
        uri = params.text_document.uri
        analysis = ls.current(uri)
        items = completion.complete(analysis, ls.named.get(uri), params.position)
        return lsp.CompletionList(is_incomplete=False, items=items)

    @ls.feature(lsp.TEXT_DOCUMENT_HOVER)
    def on_hover(ls: MpcServer, params: lsp.HoverParams) -> lsp.Hover | None:
        return hover.hover(ls.current(params.text_document.uri), params.position)

    @ls.feature(lsp.TEXT_DOCUMENT_DEFINITION)
    def on_definition(ls: MpcServer, params: lsp.DefinitionParams) -> lsp.Location | None:
        return navigation.definition(ls.current(params.text_document.uri), params.position)

    @ls.feature(lsp.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    def on_symbols(ls: MpcServer, params: lsp.DocumentSymbolParams) -> list[lsp.DocumentSymbol]:
        return navigation.symbols(ls.current(params.text_document.uri))

    @ls.feature(lsp.TEXT_DOCUMENT_RENAME)
    def on_rename(ls: MpcServer, params: lsp.RenameParams) -> lsp.WorkspaceEdit | None:
        return navigation.rename(ls.current(params.text_document.uri), params.position, params.new_name)

    @ls.feature(lsp.TEXT_DOCUMENT_CODE_ACTION,
                lsp.CodeActionOptions(code_action_kinds=[lsp.CodeActionKind.QuickFix]))
    def on_code_action(ls: MpcServer, params: lsp.CodeActionParams) -> list[lsp.CodeAction]:
        return navigation.code_actions(params.text_document.uri, params.context.diagnostics)

    return ls


def serve(packages: dict[str, Path] | None = None, debounce_ms: float | None = None) -> None:
    """Run the server on stdin and stdout until the client says exit."""
    ls = server(packages)
    gc.freeze()  # mpc's modules and the schema live as long as the server: never scan them again
    if debounce_ms is not None:
        ls.debounce = debounce_ms / 1000
    ls.start_io()

