"""What a format cannot hold, as data: a table of tallies, read by one function (`left_out`).

Each writer that leaves something out (W0500) declares a table: a tuple of tallies, each a
function of the robot and the writer's options that yields (phrase, count) pairs. `left_out`
adds the counts of equal phrases, keeps the order in which each phrase was first yielded (a
tally may yield a count of 0 to hold a phrase's place) and names those counted at least once.
`count` and `named` make the common tallies of one line.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from mpc.core.record import record
from mpc.ir.robot import Robot

Options = Mapping[str, Any]


@record
class Counted:
    """`3 motors`, `1 annotated link or joint`: a number and its noun (`many` when not 1)
    after `before`."""

    one: str
    many: str
    before: str = ""

    def say(self, n: int) -> str:
        return f"{self.before}{n} {self.many if n != 1 else self.one}"


def noun(word: str, before: str = "") -> Counted:
    """A noun whose plural adds 's'."""
    return Counted(word, word + "s", before)


@record
class Named:
    """A phrase said as it is, once (a joint by name, the submechanisms file)."""

    text: str

    def say(self, n: int) -> str:
        return self.text


Phrase = Counted | Named
Tally = Callable[[Robot, Options], Iterable[tuple[Phrase, int]]]


def count(phrase: Phrase, counter: Callable[[Robot, Options], int]) -> Tally:
    """The tally of one phrase: `counter` counts it."""
    return lambda robot, options: ((phrase, counter(robot, options)),)


def named(phrase: Named, holds: Callable[[Robot, Options], bool]) -> Tally:
    """The tally of a phrase said when the robot `holds` it."""
    return lambda robot, options: ((phrase, int(holds(robot, options))),)


def left_out(robot: Robot, table: Iterable[Tally], **options: Any) -> list[str]:
    """What `robot` holds that the format of `table` does not, one phrase each (see the
    module's docstring)."""
    counts: dict[Phrase, int] = {}
    for tally in table:
        for phrase, n in tally(robot, options):
            counts[phrase] = counts.get(phrase, 0) + n
    return [phrase.say(n) for phrase, n in counts.items() if n]
