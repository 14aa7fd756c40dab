"""`mpc lsp`: the language server of model definitions and pipeline files, over stdio (lsp/)."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of `mpc lsp` (`--package` comes from cli/main.py, as every command's)."""
    parser.add_argument("--stdio", action="store_true",
                        help="talk LSP on stdin and stdout (the default and only transport; editors pass it)")
    parser.add_argument("--debounce-ms", type=float, default=5.0, metavar="MS",
                        help="check a changed buffer once it has been quiet this long (default: 5)")


def run(args: argparse.Namespace) -> int:
    from mpc.lsp.server import serve

    serve(dict(args.package), args.debounce_ms)
    return 0
