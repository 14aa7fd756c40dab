"""`mpc lsp`: the language server of model definitions and pipeline files, over stdio (lsp/)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any


def add_arguments(parser: argparse.ArgumentParser, package: Callable[[str], Any]) -> None:
    """The options of `mpc lsp`; `package`: how `--package NAME=DIR` is parsed (cli/main.py)."""
    parser.add_argument("--stdio", action="store_true",
                        help="talk LSP on stdin and stdout (the default and only transport; editors pass it)")
    parser.add_argument("--debounce-ms", type=float, default=5.0, metavar="MS",
                        help="check a changed buffer once it has been quiet this long (default: 5)")
    parser.add_argument("--package", type=package, action="append", default=[], metavar="NAME=DIR",
                        help="where the ROS package NAME is (for package:// paths); repeatable")


def run(args: argparse.Namespace) -> int:
    from mpc.lsp.server import serve

    serve(dict(args.package), args.debounce_ms)
    return 0
