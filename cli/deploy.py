"""`mpc deploy`: deploy an existing build of one model definition (cli/main.py parses
the arguments and calls `run`). Exit status: 0 deployed (or nothing to do), 1 failed."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from mpc.deploy import FORGES

if TYPE_CHECKING:  # the rest is imported by `run`: building the parser of `mpc` stays light
    from mpc.core.diagnostics import Sink
    from mpc.deploy.result import DeployResult
    from mpc.deploy.settings import DeploySettings


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of `mpc deploy` (`--package`, `--format` and `--werror` come from
    cli/main.py, as every command's that reads definitions)."""
    parser.add_argument("definition", type=Path,
                        help="the model definition (YAML) whose build is deployed")
    parser.add_argument("--built", type=Path, required=True, metavar="DIR",
                        help="the compiled model (what `mpc compile -o DIR` wrote)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--pipeline", type=Path,
                       help="pipeline.yml: remote_base, forge, LFS, meshes, defaults")
    where.add_argument("--remote", help="the address of the model's repository")
    parser.add_argument("--forge", choices=FORGES,
                        help="how merge requests are made (default: the pipeline's, else none)")
    parser.add_argument("--dry-run", action="store_true", help="print the diff stat that would be pushed")
    parser.add_argument("--protocol", type=Path, metavar="FILE",
                        help="the test protocol (Markdown), appended to the merge request")
    parser.add_argument("--tests-failed", action="store_true",
                        help="the model failed its tests: deploy to the failure branch")
    parser.add_argument("--success-branch", help="default: $GIT_SUCCESS_BRANCH, else the remote's default")
    parser.add_argument("--failure-branch",
                        help="default: $GIT_FAILURE_BRANCH, else $CI_UPDATE_TARGET_BRANCH, else tests-failed")
    parser.add_argument("--workdir", type=Path,
                        help="where mpc keeps its clones (default: <pipeline root>/.mpc-deploy, "
                             "else build/.deploy)")


def run(args: argparse.Namespace) -> int:
    from mpc.cli.output import resolver_of, sink_of
    from mpc.compiler.driver import Options
    from mpc.compiler.front_end import load_program
    from mpc.core.diagnostics import Severity
    from mpc.core.render import print_diagnostics
    from mpc.deploy.model import deploy_model

    sink = sink_of(args)
    # A build exists already: what `compile` does not support yet is no reason to refuse it.
    program = load_program(args.definition, sink, Options(resolver=resolver_of(args)), Severity.WARNING)
    settings = _settings(args, sink)
    protocol = None if args.protocol is None else _read_protocol(args.protocol, sink)
    result = None
    if program is not None and settings is not None and not sink.has_errors():
        pictures = None if args.protocol is None else args.protocol.parent / "test_pictures"
        from mpc.checks.diff_review import review_of

        result = deploy_model(program, args.built, settings, sink, protocol_markdown=protocol,
                              tests_failed=args.tests_failed, pictures=pictures,
                              review=review_of(program, args.built.resolve()))
    print_diagnostics(sink.diagnostics, args.format)
    if result is None or not result.ok:
        print(f"error: could not deploy '{args.definition}'", file=sys.stderr)
        return 1
    _report(result, "")
    return 0


def _read_protocol(path: Path, sink: Sink) -> str | None:
    """The test protocol's text; E0802 when it cannot be read or is not UTF-8."""
    from mpc.core.span import Span

    try:
        return path.read_text(encoding="utf-8")
    except OSError as e:
        problem = e.strerror
    except UnicodeDecodeError as e:
        problem = f"it is not UTF-8 text (byte 0x{e.object[e.start]:02x} at offset {e.start})"
    sink.error(Span.of_file(str(path)), "E0802", f"cannot read the test protocol: {problem}")
    return None


def _settings(args: argparse.Namespace, sink: Sink) -> DeploySettings | None:
    from mpc.deploy.settings import DeploySettings

    values = {"remote": args.remote, "forge": args.forge, "dry_run": args.dry_run or None,
              "success_branch": args.success_branch, "failure_branch": args.failure_branch,
              "workdir": args.workdir}
    if args.pipeline is None:
        return DeploySettings.from_environment(
            definition_repo=args.definition.resolve().parent,
            **{**values, "forge": args.forge or "none"})
    from mpc.compiler import schema
    from mpc.core import yaml_source as source

    doc = source.load(args.pipeline, sink)
    pipeline = schema.validate_pipeline(doc, sink) if doc is not None else None
    if pipeline is None:
        return None
    return DeploySettings.from_pipeline(pipeline.pipeline, args.pipeline.resolve().parent, sink, **values)


def _report(result: DeployResult, indent: str) -> None:
    from mpc.deploy.gitcmd import scrub

    where = f"branch '{result.branch}' of '{scrub(result.remote or '')}'"
    if result.skipped:
        print(f"{indent}'{result.modelname}' is not deployed (do_not_deploy)")
    elif result.diffstat:
        print(f"{indent}dry run: would push to {where}:\n{result.diffstat}")
    elif result.commit is None:
        print(f"{indent}'{result.modelname}': nothing changed on {where}")
    else:
        print(f"{indent}deployed '{result.modelname}' to {where}: commit {result.commit[:12]}")
    for kind, sha in sorted(result.meshes.items()):
        print(f"{indent}  {kind}: mesh repository at commit {sha[:12]}")
    if result.merge_request is not None:
        print(f"{indent}  merge request into '{result.merge_request.target}'"
              f"{': ' + result.merge_request_url if result.merge_request_url else ''}")
    if result.mirror is not None:
        _report(result.mirror, indent + "mirror: ")

