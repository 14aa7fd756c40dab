"""Every subcommand that reads definitions takes the same input options (cli/main.py's
parents): `--package`, and where diagnostics are printed, `--format` and `--werror`."""

from __future__ import annotations

import argparse

from mpc.cli.main import _parser

READERS = {"compile", "check", "test", "deploy", "run", "view", "ci job"}
INPUTS = {"--package", "--format", "--werror"}


def _subcommands(parser: argparse.ArgumentParser, prefix: str = "") -> dict[str, argparse.ArgumentParser]:
    out = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out[prefix + name] = sub
                out.update(_subcommands(sub, f"{prefix}{name} "))
    return out


def _options(parser: argparse.ArgumentParser) -> set[str]:
    return {option for action in parser._actions for option in action.option_strings}


def test_every_command_that_reads_definitions_takes_the_same_input_options() -> None:
    commands = _subcommands(_parser())
    assert {name for name, sub in commands.items() if _options(sub) >= INPUTS} == READERS
    assert "--package" in _options(commands["lsp"])  # it prints no diagnostics: it sends them
    helps = {name: next(a.help for a in commands[name]._actions if "--package" in a.option_strings)
             for name in (*READERS, "lsp")}
    assert len(set(helps.values())) == 1, helps
