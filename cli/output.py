"""What every subcommand of `mpc` shares: its sink, the package resolver of its `--package`
options, and printing diagnostics and their summary. Nothing here parses arguments."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mpc.core.diagnostics import Sink
    from mpc.core.packages import PackageResolver


def sink_of(args: argparse.Namespace) -> Sink:
    from mpc.core.diagnostics import Sink

    return Sink(werror=args.werror)


def resolver_of(args: argparse.Namespace) -> PackageResolver:
    """The packages of `--package NAME=DIR`, then the usual search (core/packages.py)."""
    from mpc.core.packages import PackageResolver

    return PackageResolver(package_map=dict(args.package))


def summary(sink: Sink) -> str:
    """"2 errors, 1 warning"."""
    from mpc.core import render

    return render.summary(sink.diagnostics)


def print_diagnostics(sink: Sink, fmt: str) -> None:
    from mpc.core import render

    render.print_diagnostics(sink.diagnostics, fmt)
