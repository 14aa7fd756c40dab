"""`mpc check FILE…`: a model definition, an IR file or a pipeline file, checked; nothing written.

The command tells a pipeline file from a model definition by reading it once; a definition
then goes through the driver's front end without the pipeline's modules being imported.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mpc.cli.output import print_diagnostics, resolver_of, sink_of, summary
from mpc.compiler import front_end
from mpc.compiler.options import Options
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Sink
from mpc.core.files import describe
from mpc.core.span import Span


def check_file(path: Path, sink: Sink, options: Options) -> None:
    """Everything `mpc check` does for one file: a pipeline file through check_pipeline, with
    each of its definitions under the pipeline's defaults; anything else through the front end."""
    if path.suffix == ".ir":
        front_end.check_file(path, sink, options)
        return
    try:
        doc = source.load(path, sink)
    except OSError as e:
        sink.error(Span.of_file(str(path)), "E0661", describe(e, "read an input of the model"))
        return
    if doc is None:
        return
    if isinstance(doc.data, dict) and "pipeline" in doc.data:
        from mpc.pipeline.plan import check_pipeline_file

        check_pipeline_file(path, sink, options)
        return
    front_end.check_file(path, sink, options, doc)


def run(args: argparse.Namespace) -> int:
    """`mpc check FILE…`: 1 when a file has errors."""
    sink = sink_of(args)
    options = Options(resolver=resolver_of(args))
    for path in args.files:
        check_file(path, sink, options)
    print_diagnostics(sink, args.format)
    if args.format == "human" and sink.diagnostics:
        print(f"{summary(sink)} in {len(args.files)} file"
              f"{'s' * (len(args.files) != 1)}", file=sys.stderr)
    return 1 if sink.has_errors() else 0
