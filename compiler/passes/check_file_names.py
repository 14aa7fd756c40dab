"""check_file_names (`mpc check` and compile): names of the model that exports make file names.

Two exports build a file name from a name of the model: the ROS package (`ros_pathes`,
`copy_with_other_pathes`) writes each pose as `config/init_positions_<pose>.yml`, and `kccd`
writes each body's hull as `meshes/iv/collision_<link>.stl`. A name that cannot be one file
name (a '/', '..', an absolute path: core/files.py `name_problem`) is E0540, reported where the
name comes from: the line of the definition that made it (a `poses` entry, a `name_editing`
prefix) or the input model's line that holds it. The backends refuse such a name too
(core/files.py `file_name`; E0540 at the export): this pass says so before anything is built, and where.
"""

from __future__ import annotations

from collections.abc import Callable

from mpc.core.span import Span
from mpc.ir.names import Kind, Names
from mpc.ir.ops import LoadModel, Op
from mpc.ir.program import Input, KccdExport, Program, RosPackageExport

# Where a name of each kind becomes a file: the file, as the message names it.
ROUTES: dict[type, tuple[Kind, str]] = {
    RosPackageExport: ("pose", "config/init_positions_<pose>.yml of the ROS package"),
    KccdExport: ("link", "meshes/iv/collision_<link>.stl of the kccd export"),
}

# Where an input model holds one of its names (None: the input's own line).
NameSpan = Callable[[Input, Kind, str], "Span | None"]


def file_routes(program: Program) -> dict[Kind, str]:
    """The kinds of names the program's exports turn into file names, and into which file."""
    return dict(ROUTES[type(e)] for e in program.exports if type(e) in ROUTES)


class Origins:
    """Where each name of the routed kinds was made: by an op of the definition (its span), or
    by an input model (the input); fed by check_names' trace."""

    def __init__(self, kinds: dict[Kind, str]) -> None:
        self.kinds = kinds
        self.by_op: dict[tuple[Kind, str], Span] = {}

    def trace(self, op: Op, before: Names, after: Names) -> None:
        for kind in self.kinds:
            for name in after.all(kind) - before.all(kind):
                self.by_op.setdefault((kind, name), op.span)


def check_file_names(program: Program, names: Names, origins: Origins,
                     input_names: Callable[[Input], Names | None], name_span: NameSpan,
                     report: Callable[[Span, str], None]) -> None:
    """E0540 for each name of the finished robot that a route makes a file name and that
    cannot be one."""
    from mpc.core.files import name_problem

    for kind, route in origins.kinds.items():
        for name in sorted(names.all(kind)):
            why = name_problem(name)
            if why is None:
                continue
            span = origins.by_op.get((kind, name)) or _input_span(program, kind, name, input_names,
                                                                   name_span)
            report(span, f"the {kind} name '{name}' cannot be a file name, and the export makes "
                         f"it {route}: {why}")


def _input_span(program: Program, kind: Kind, name: str,
                input_names: Callable[[Input], Names | None], name_span: NameSpan) -> Span:
    """The line of the input model that holds `name`, else that input's line in the definition."""
    for op in program.ops:
        if isinstance(op, LoadModel):
            inp = program.inputs[op.input]
            found = input_names(inp)
            if found is not None and name in found.all(kind):
                return name_span(inp, kind, name) or inp.span
    return program.span
