"""`mpc schema`: the JSON Schema of the definition language, on stdout or into a file."""

from __future__ import annotations

import argparse
import sys


def run(args: argparse.Namespace) -> int:
    from mpc.compiler.jsonschema import render as render_schema

    text = render_schema()
    if args.out is None or str(args.out) == "-":
        sys.stdout.write(text)
    else:
        from mpc.core.files import write_atomic

        write_atomic(args.out, text)
        print(f"wrote {args.out}")
    return 0
