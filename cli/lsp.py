"""`mpc lsp`: the language server of model definitions and pipeline files, over stdio (lsp/)."""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of `mpc lsp` (`--package` comes from cli/main.py, as every command's)."""
    parser.add_argument("--stdio", action="store_true",
                        help="talk LSP on stdin and stdout (the default and only transport; editors pass it)")
    parser.add_argument("--debounce-ms", type=float, default=5.0, metavar="MS",
                        help="check a changed buffer once it has been quiet this long (default: 5)")


def run(args: argparse.Namespace) -> int:
    without_openssl_hashes()
    from mpc.lsp.server import serve

    return serve(dict(args.package), args.debounce_ms)


def without_openssl_hashes() -> None:
    """The server's process hashes with Python's own hash functions, not OpenSSL's.

    mpc's own modules import `hashlib` (core/version.py, core/cache.py), which loads OpenSSL's
    libcrypto through `_hashlib`: 3.5 MiB of the server's memory, to hash little in a check
    (mpc's build cache hashes; the server builds nothing). `None` in `sys.modules` makes an
    import fail, as the import system documents; `hashlib` and `hmac` then give their
    functions from Python's built-in modules (the same digests, slower on large data). Nothing
    is changed once `_hashlib` is imported, nor in a program that only imports mpc's modules.
    """
    sys.modules.setdefault("_hashlib", None)  # type: ignore[arg-type]
