"""`mpc compile DEFINITION`: the model files in the output folder, or the IR on stdout (`--emit`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mpc.cli.output import print_diagnostics, resolver_of, sink_of, summary


def run(args: argparse.Namespace) -> int:
    from mpc.compiler.driver import Options, compile_model

    sink = sink_of(args)
    options = Options(out=args.out, resolver=resolver_of(args), force=args.force,
                      post_processing=not args.no_post_processing)
    if args.emit in ("ir", "ir-lowered"):
        from mpc.compiler.front_end import load_program
        from mpc.ir.text import dump

        program = load_program(args.definition, sink, options, passes=args.emit == "ir")
        print_diagnostics(sink, args.format)
        if program is None:
            return 1
        sys.stdout.write(dump(program))
        return 0
    result = compile_model(args.definition, sink, options)
    print_diagnostics(sink, args.format)
    if result.out is None:
        if args.format == "human":
            print(f"error: could not compile '{args.definition}' ({summary(sink)})",
                  file=sys.stderr)
        return 1
    files = sorted(str(p.relative_to(result.out)) for p in result.out.rglob("*") if p.is_file())
    models = [f for f in files if "meshes" not in Path(f).parts]
    print(f"compiled '{args.definition}' into '{result.out}': {', '.join(models)} "
          f"and {len(files) - len(models)} mesh files")
    return 0
