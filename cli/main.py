"""The `mpc` command: argument parsing, dispatch to one module per subcommand (COMMANDS), exit codes.

Exit status: 0 success, 1 the input has errors, 2 the command line is wrong,
3 mpc itself failed (a bug: please report it; MPC_DEBUG=1 shows the traceback).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple, NoReturn

# The rest of mpc is imported by the command that needs it (COMMANDS): `mpc check` turns off
# the cyclic garbage collector first (_without_cyclic_gc), and no command pays for another's
# imports.


def _package(text: str) -> tuple[str, Path]:
    name, sep, folder = text.partition("=")
    if not sep or not name or not folder:
        raise argparse.ArgumentTypeError(f"expected NAME=DIR, got '{text}'")
    return name, Path(folder).resolve()


def _input_parents() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The options of every command that reads definitions, as argparse parents: how packages
    are found (`--package`: every such command, `mpc lsp` too) and how diagnostics are printed
    and judged (`--format`, `--werror`: every such command that prints them)."""
    packages = argparse.ArgumentParser(add_help=False)
    packages.add_argument("--package", type=_package, action="append", default=[], metavar="NAME=DIR",
                          help="where the ROS package NAME is (for package:// paths); repeatable")
    diagnostics = argparse.ArgumentParser(add_help=False)
    diagnostics.add_argument("--format", choices=("human", "gcc", "json"), default="human",
                             help="how to print diagnostics (default: human)")
    diagnostics.add_argument("--werror", action="store_true", help="treat warnings as errors")
    return packages, diagnostics


class _Version(argparse.Action):
    """--version, which reads the installed metadata only when asked (not on every start)."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)  # type: ignore[arg-type]

    def __call__(self, parser: argparse.ArgumentParser, *_: object) -> None:
        from mpc.core.version import mpc_version

        print(f"mpc {mpc_version()}")
        parser.exit()


def _compile_arguments(comp: argparse.ArgumentParser) -> None:
    comp.add_argument("definition", type=Path, help="the model definition (YAML), or an IR file (.ir)")
    comp.add_argument("-o", "--out", type=Path, help="output folder (default: build/<modelname>)")
    comp.add_argument("--emit", choices=("files", "ir", "ir-lowered"), default="files",
                      help="what to produce: the model files (default), or the IR as text on stdout: "
                           "after the passes (ir) or as lowered, before them (ir-lowered)")
    comp.add_argument("--force", action="store_true",
                      help="build anew even when nothing the last build read has changed (its kept "
                           "outputs are not used; the mesh cache is)")
    comp.add_argument("--no-post-processing", action="store_true",
                      help="do not run the definition's post_processing commands")


def _check_arguments(check: argparse.ArgumentParser) -> None:
    check.add_argument("files", type=Path, nargs="+", metavar="FILE",
                       help="model definitions, IR files or pipeline.yml files")


def _schema_arguments(schema: argparse.ArgumentParser) -> None:
    schema.add_argument("-o", "--out", type=Path, help="the file to write it to (default: stdout)")


def _deploy_arguments(deploy: argparse.ArgumentParser) -> None:
    from mpc.cli.deploy import add_arguments

    add_arguments(deploy)


def _test_arguments(test: argparse.ArgumentParser) -> None:
    test.add_argument("definition", type=Path, help="the model definition (YAML), or an IR file (.ir)")
    test.add_argument("--built", type=Path, help="test this compiled output instead of compiling")
    test.add_argument("-o", "--out", type=Path, help="output folder (default: build/<modelname>); with "
                      "--built: where the protocol goes (default: the --built folder)")


def _diff_arguments(diff: argparse.ArgumentParser) -> None:
    from mpc.cli.diff import add_arguments

    add_arguments(diff)


def _root_outside(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--allow-root-outside", action="store_true",
                        help="accept a pipeline `root` outside the pipeline file's folder and its parent "
                             "(the build folder is <root>/build)")


def _run_arguments(run: argparse.ArgumentParser) -> None:
    run.add_argument("pipeline", type=Path, help="the pipeline file")
    run.add_argument("--only", nargs="+", action="extend", default=[], metavar="MODEL",
                     help="build only these models (modelnames or definition files); others' outputs stay")
    run.add_argument("--stages", default="compile", metavar="STAGE,…",
                     help="stages to run, comma-separated: compile, test, deploy (default: compile)")
    run.add_argument("-j", "--jobs", type=int, default=None, metavar="N",
                     help="models built at once (default: the number of cores)")
    run.add_argument("--force", action="store_true", help="rebuild even what is unchanged")
    run.add_argument("--no-post-processing", action="store_true",
                     help="do not run the definitions' post_processing commands")
    run.add_argument("-o", "--out", type=Path, help="the build folder (default: <root>/build)")
    run.add_argument("--verify", action="store_true",
                     help="fail unless every selected stage of every selected model is ok or cached")
    run.add_argument("--allow-na", action="store_true",
                     help="with --verify: stages that skipped by their own choice (not applicable) pass")
    run.add_argument("--log-format", choices=("text", "json"), default="text",
                     help="progress: text (live on a terminal, quiet otherwise) or JSON lines on stdout")
    _root_outside(run)


def _ci_arguments(ci: argparse.ArgumentParser) -> None:
    systems = ci.add_subparsers(dest="system", required=True, metavar="gitlab|github|job|summary|review")
    gens = []
    for system, what in (("gitlab", "a GitLab CI child pipeline"), ("github", "a GitHub Actions workflow")):
        gen = systems.add_parser(system, help=f"write {what}")
        gens.append(gen)
        gen.add_argument("pipeline", type=Path, help="the pipeline file")
        gen.add_argument("-o", "--output", type=Path, help="where to write the YAML (default: stdout)")
        gen.add_argument("--stages", default="compile", metavar="STAGE,…",
                         help="stages to run, each in jobs of its own (default: compile)")
        gen.add_argument("--image", help="container image of the jobs (GitLab image, GitHub container); "
                         "without --install, the jobs use the mpc the image has")
        gen.add_argument("--install", "--setup", dest="install", metavar="CMD",
                         help="shell command that installs mpc in a job and puts it on PATH (default: "
                         "the install of this mpc, from the project's requirements.txt or how it was "
                         "installed)")
    job = systems.add_parser("job", parents=list(_input_parents()),
                             help="what a generated job runs: one model and stages, with the artifacts "
                                  "of earlier jobs")
    job.add_argument("pipeline", type=Path, help="the pipeline file")
    job.add_argument("model", help="the modelname")
    job.add_argument("-o", "--out", type=Path, help="the build folder (default: <root>/build)")
    job.add_argument("--stages", default="compile", metavar="STAGE,…", help="stages to run")
    summary = systems.add_parser("summary", help="what the last job runs: every job's status merged")
    summary.add_argument("pipeline", type=Path, help="the pipeline file")
    summary.add_argument("-o", "--out", type=Path, help="the build folder (default: <root>/build)")
    summary.add_argument("--markdown", type=Path, metavar="FILE",
                         help="also append the table as Markdown to FILE (GitHub: $GITHUB_STEP_SUMMARY)")
    review = systems.add_parser("review", help="in a merge request's pipeline: every model's changes "
                                "against the request's base, posted as a comment (GitLab, GitHub)")
    review.add_argument("pipeline", type=Path, help="the pipeline file")
    review.add_argument("--base", metavar="REV", help="compare with the definitions at this git revision "
                        "(default: the merge request's base)")
    for p in (*gens, job, summary, review):
        _root_outside(p)


def _lsp_arguments(lsp: argparse.ArgumentParser) -> None:
    from mpc.cli.lsp import add_arguments

    add_arguments(lsp)


def _view_arguments(view: argparse.ArgumentParser) -> None:
    view.add_argument("model", type=Path, help="a model definition (YAML or .ir) or a built folder")
    view.add_argument("--compare", metavar="DIR|URL@REF", help="draw this model as a ghost: a folder, "
                      "or a git repository at a branch or commit")
    view.add_argument("--host", default="127.0.0.1", help="the address to bind (default: 127.0.0.1)")
    view.add_argument("--port", type=int, default=8080, help="the port (default: 8080; 0: any free one)")


def _parser(command: str | None = None) -> argparse.ArgumentParser:
    """mpc's argument parser; with `command`, that subcommand's alone (the one on the command
    line: argparse builds every argument and asks gettext for every parser's messages, 15 ms of
    each mpc process when all ten commands are built)."""
    parser = argparse.ArgumentParser(prog="mpc", description="mpc, the model pipeline compiler")
    parser.add_argument("--version", action=_Version, help="print mpc's version and exit")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    packages, diagnostics = _input_parents()
    parents = {"inputs": [packages, diagnostics], "packages": [packages], "": []}
    for name, entry in COMMANDS.items():
        if command is None or command == name:
            entry.add_arguments(sub.add_parser(name, parents=parents[entry.shared], help=entry.help))
    return parser


# Each subcommand: a function of the parsed arguments (→ exit status) that imports its module
# only when called (no command pays for another's imports), by name, so that import-linter
# sees the import.
def _compile(args: argparse.Namespace) -> int:
    from mpc.cli import compile as compile_command

    return compile_command.run(args)


def _check(args: argparse.Namespace) -> int:
    from mpc.cli import check

    return check.run(args)


def _schema(args: argparse.Namespace) -> int:
    from mpc.cli import schema

    return schema.run(args)


def _test(args: argparse.Namespace) -> int:
    from mpc.cli import test

    return test.run(args)


def _diff(args: argparse.Namespace) -> int:
    from mpc.cli import diff

    return diff.run(args)


def _deploy(args: argparse.Namespace) -> int:
    from mpc.cli import deploy

    return deploy.run(args)


def _run(args: argparse.Namespace) -> int:
    from mpc.cli import run

    return run.run(args)


def _ci(args: argparse.Namespace) -> int:
    from mpc.cli import run

    return run.ci(args)


def _view(args: argparse.Namespace) -> int:
    from mpc.cli import view

    return view.run(args)


def _lsp(args: argparse.Namespace) -> int:
    from mpc.cli import lsp

    return lsp.run(args)


class Command(NamedTuple):
    """A subcommand: its help as `mpc --help` lists it, the options it shares (`_input_parents`:
    "inputs" both, "packages" --package alone), what adds its own arguments, and what runs it."""

    help: str
    shared: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


COMMANDS: dict[str, Command] = {  # in the order of `mpc --help`
    "compile": Command("compile a model definition into model files", "inputs", _compile_arguments,
                       _compile),
    "check": Command("check definitions (or pipeline files) without building", "inputs", _check_arguments,
                     _check),
    "schema": Command("write the JSON Schema of the definition language", "", _schema_arguments, _schema),
    "deploy": Command("deploy a built model to its git repository", "inputs", _deploy_arguments, _deploy),
    "test": Command("compile a model definition and run its model tests", "inputs", _test_arguments, _test),
    "diff": Command("the semantic changes between two models (exit 1 when something changed, as diff)", "",
                    _diff_arguments, _diff),
    "run": Command("build every model of a pipeline.yml (DAG, cache, parallel workers)", "inputs",
                   _run_arguments, _run),
    "ci": Command("write a CI pipeline with one job per model (GitLab or GitHub)", "", _ci_arguments, _ci),
    "lsp": Command("the language server for editors (LSP over stdio)", "packages", _lsp_arguments, _lsp),
    "view": Command("show a model in the browser (a local web viewer)", "inputs", _view_arguments, _view),
}


def _without_cyclic_gc(command: str) -> contextlib.AbstractContextManager[None]:
    """`mpc check` and `mpc compile` are short-lived and reference counting frees their garbage;
    collecting cycles among the tens of thousands of objects their imports create costs ~15 ms
    of `mpc check` for nothing, and of the 88-link assembly's build 15 ms warm, 38 ms cold, to
    find about a thousand objects (what `mpc run`'s workers build is collected as usual).
    In a process that ends after the command (program()), the collector is not turned on
    again: the first allocation after would scan everything once more, 9 ms of a cold build."""
    from mpc.core.cycles import paused_cycle_collection

    if command not in ("check", "compile"):
        return contextlib.nullcontext()
    if _process_ends:
        gc.disable()
        return contextlib.nullcontext()
    return paused_cycle_collection()


_process_ends = False  # program() runs main(), then ends the process


def _json_on_stdout(args: argparse.Namespace) -> bool:
    """`--format json` makes stdout one JSON document of diagnostics, unless stdout carries
    something else already: the IR of `--emit ir`, the JSON lines of `--log-format json`."""
    return (getattr(args, "format", None) == "json" and getattr(args, "emit", None) != "ir"
            and args.command != "diff"  # its stdout is the diff
            and getattr(args, "log_format", None) != "json")


def main(argv: list[str] | None = None) -> int:
    from mpc.core import blas

    blas.one_thread()  # before anything imports numpy
    if not os.environ.get("MPC_DEBUG"):
        # The libraries' own warnings (numpy's RuntimeWarning in trimesh on a mesh with a
        # coordinate of 3.4e38) name their source lines, not the user's file: what they point
        # at is a diagnostic where it matters. MPC_DEBUG=1 shows them.
        warnings.simplefilter("ignore")
    words = sys.argv[1:] if argv is None else argv
    args = _parser(words[0] if words and words[0] in COMMANDS else None).parse_args(argv)
    if _process_ends and args.command in ("compile", "run"):  # builds (`run` forks one a model)
        from mpc.core.heap import keep_freed

        keep_freed()  # what a mesh job frees, the next one reuses (core/heap.py)
    try:
        with _without_cyclic_gc(args.command):
            command = COMMANDS[args.command].run
            if _json_on_stdout(args):
                from mpc.core.render import json_document

                with json_document():
                    return command(args)
            return command(args)
    except KeyboardInterrupt:
        return 130
    except OSError as e:  # the disk, not mpc: what no phase reported with its own code
        if os.environ.get("MPC_DEBUG"):
            raise
        from mpc.core.files import describe

        code = "E0669"
        print(f"error[{code}]: {describe(e, f'finish mpc {args.command}')}", file=sys.stderr)
        return 1
    except Exception as e:  # a bug in mpc, not a user mistake
        if os.environ.get("MPC_DEBUG"):
            raise
        print(f"internal error: {type(e).__name__}: {e}\nThis is a bug in mpc; rerun with "
              "MPC_DEBUG=1 for the traceback and please report it.", file=sys.stderr)
        return 3


def program() -> NoReturn:
    """`mpc` as a program (the console script, `python -m mpc.cli.main`): main(), then an end
    without the interpreter's teardown.

    Python frees every object of every module at exit; after a build that loaded trimesh and
    SciPy that took 0.2 s, a tenth of a cold build. What of the teardown matters is done here
    first: the atexit functions (multiprocessing's, tempfile's, logging's) and the standard
    streams, C's too (what a C library printed); mpc's own files are closed when written
    (core/files.py). A process that still runs another thread, or runs under a profiler or
    tracer (cProfile, coverage: they write their results at the end), ends the usual way."""
    global _process_ends
    _process_ends = True
    try:
        code = main()
    except SystemExit as e:
        if not isinstance(e.code, int | None):
            raise
        code = e.code or 0
    import atexit
    import threading  # here: not on the path of `mpc check` before it has answered

    if threading.active_count() > 1 or sys.gettrace() is not None or sys.getprofile() is not None:
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a closed pipe: what it took is all there is
            stream.flush()
    with contextlib.suppress(ImportError, OSError, AttributeError):  # C's streams: PyBullet prints
        import ctypes

        ctypes.CDLL(None).fflush(None)
    os._exit(code)


if __name__ == "__main__":
    program()
