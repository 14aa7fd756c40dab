"""`mpc test DEFINITION`: compile (unless --built names an output), run the model tests, write
the protocol into the output folder and print its Markdown."""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from mpc.cli.output import print_diagnostics, resolver_of, sink_of, summary
from mpc.core.files import resolved


def run(args: argparse.Namespace) -> int:
    """1 when a test failed and was not waived, or nothing could be tested."""
    from mpc.checks import run_model_tests
    from mpc.compiler.driver import Options, compile_model
    from mpc.compiler.front_end import input_loader, load_program
    from mpc.compiler.ops_run import apply

    sink = sink_of(args)
    options = Options(out=args.out, resolver=resolver_of(args))
    if args.built is not None:
        loader = input_loader(sink, options, (resolved(args.definition),))
        program = load_program(args.definition, sink, options, loader=loader)
        robot = apply(program, sink, loader) if program is not None else None
        out = args.built
        if program is not None and not out.is_dir():
            print(f"error: --built '{out}' is not a folder", file=sys.stderr)
            return 1
    else:
        result = compile_model(args.definition, sink, options)
        program, robot, out = result.program, result.robot, result.out
    if program is None or robot is None or out is None:
        print_diagnostics(sink, args.format)
        print(f"error: could not compile '{args.definition}' ({summary(sink)})",
              file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="mpc-test-") as work:
        protocol = run_model_tests(program, out, sink, workdir=Path(work), robot=robot)
    target = args.out if args.built is not None and args.out is not None else out  # -o with --built
    print_diagnostics(sink, args.format)
    print(protocol.markdown())
    try:
        protocol.write(target)
    except OSError as e:
        print(f"error: cannot write the test protocol into '{target}': {e.strerror or e}", file=sys.stderr)
        return 1
    print(f"wrote {target / 'test_protocol.md'}, test_protocol.json and test_protocol.junit.xml",
          file=sys.stderr)
    return 1 if protocol.failed else 0
