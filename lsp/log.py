"""The server's log: lines on stderr, which editors show as the language server's log.

Not the logging module, which nothing else in the server's process needs and which would
take about 1 MiB of its memory with what it imports.
"""

from __future__ import annotations

import sys


def warn(text: str) -> None:
    """A line: what the server refused or dropped, and why."""
    sys.stderr.write(f"mpc lsp: {text}\n")
    sys.stderr.flush()


def fault(text: str) -> None:
    """A line and the traceback of the exception being handled: a fault of mpc's own."""
    import traceback

    sys.stderr.write(f"mpc lsp: {text}\n{traceback.format_exc()}")
    sys.stderr.flush()
