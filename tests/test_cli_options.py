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



def _described(parser: argparse.ArgumentParser) -> dict[str, list[tuple[object, ...]]]:
    """The arguments of `parser` ("") and of each of its subcommands, as argparse holds them."""
    return {name: [(tuple(a.option_strings), a.dest, a.nargs, a.const, a.default, a.type, a.help,
                    a.metavar, a.required, None if isinstance(a, argparse._SubParsersAction) else a.choices)
                   for a in sub._actions]
            for name, sub in {"": parser, **_subcommands(parser)}.items()}


def test_a_command_s_parser_built_alone_is_the_one_of_all_commands() -> None:
    """`mpc COMMAND …` builds that command's arguments alone (cli/main.py `_parser`): the same
    arguments, options and help as when every command is built (`mpc --help`, a mistyped
    command); the others are not built."""
    from mpc.cli.main import COMMANDS

    everything = _described(_parser())
    assert sorted(name for name in everything if name and " " not in name) == sorted(COMMANDS)
    for command in COMMANDS:
        alone = _described(_parser(command))
        assert alone == {name: arguments for name, arguments in everything.items()
                         if name in ("", command) or name.startswith(command + " ")}, command
