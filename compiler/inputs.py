"""Input models, loaded once per compilation: the robot of a file, of another definition's
output (`derived_base`), or of a file in a git repository (`repo`); or just their names.

A `derived_base` is compiled in memory (its front end and ops, no emission); a cycle
of derived_base definitions is a diagnostic naming the loop.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from mpc.compiler.options import Options
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.files import project_root, why_absent
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.geometry import Mesh
from mpc.ir.names import Names
from mpc.ir.program import Input
from mpc.ir.robot import Robot

# How a derived_base definition is built, or its names found (compiler/front_end.py's `build`
# and `names_of`, handed to the loader so that loading inputs does not import the front end).
Build = Callable[[Path, Sink, Options, tuple[Path, ...]], Robot | None]
FindNames = Callable[[Path, Sink, Options, tuple[Path, ...]], Names | None]


@record(frozen=False)
class InputLoader:
    """Loads input models for one compilation (and the derived_base definitions below it).

    stack: the definitions being compiled, outermost first (to find cycles).
    symbolic: find the names of derived_base inputs without building them (`mpc check`).
    build, names_of: how a derived_base definition is built or its names found
        (compiler/front_end.py `input_loader` gives them).
    """

    sink: Sink
    options: Options
    stack: tuple[Path, ...] = ()
    symbolic: bool = False
    build: Build | None = None
    names_of: FindNames | None = None
    _robots: dict[tuple[str, str], Robot | None] = field(default_factory=dict)
    _names: dict[tuple[str, str], Names | None] = field(default_factory=dict)
    missing_meshes: list[Diagnostic] = field(default_factory=list)  # symbolic: E0602, reported last

    def __post_init__(self) -> None:
        for definition in self.stack:  # inputs are read inside their definitions' projects
            self.options.resolver.add_project(project_root(definition.parent))

    def _key(self, inp: Input) -> tuple[str, str]:
        return (inp.kind, str(inp.path) if inp.path else repr(inp.repo))

    def _cycle(self, inp: Input) -> bool:
        assert inp.path is not None
        if inp.path in self.stack:
            loop = [p.name for p in self.stack[self.stack.index(inp.path):]] + [inp.path.name]
            self.sink.error(inp.span, "E0308", "derived_base cycle: " + " → ".join(loop))
            return True
        return False

    def robot(self, inp: Input) -> Robot | None:
        """The input's robot, read or compiled once; None after reporting why."""
        key = self._key(inp)
        if key not in self._robots:
            from mpc.core.profile import stage

            with stage("load inputs"):
                self._robots[key] = self._load(inp)
        return self._robots[key]

    def loaded(self) -> list[Robot]:
        """The input models read so far."""
        return [robot for robot in self._robots.values() if robot is not None]

    def _load(self, inp: Input) -> Robot | None:
        if inp.kind == "basefile":
            if inp.path is None:  # its package was not found; reported when lowering
                return None
            return self._read(inp.path, inp)
        if inp.kind == "derived_base":
            assert inp.path is not None
            if self._cycle(inp) or self._refused(inp.path, inp):
                return None
            assert self.build is not None, "derived_base inputs need driver.input_loader's loader"
            return self.build(inp.path, self.sink, self.options, (*self.stack, inp.path))
        path = self._repo_file(inp, fetch=True)
        return None if path is None else self._read(path, inp)

    def _read(self, path: Path, inp: Input) -> Robot | None:
        """A model file, by its extension: URDF, SDF, SMURF, or a xacro (expanded with its args)."""
        if self._refused(path, inp):
            return None
        if self.options.models is not None:
            expanded_with = (*inp.xacro_args, *(("$(env)", name) for name in inp.xacro_env))
            return self.options.models.read(path, expanded_with, self.sink,
                                            lambda sink: self._parse(path, inp, sink))
        return self._parse(path, inp, self.sink)

    def _refused(self, path: Path, inp: Input) -> bool:
        """Whether the input's file lies outside the project and the package roots, or is a
        special file (core/files.py: input_problem), after reporting it at the key naming it."""
        if why := self.options.resolver.refusal(path):
            key = "derived_base" if inp.kind == "derived_base" else "input model"
            self.sink.error(inp.span, "E0650", f"{key} '{path}' is not read: {why}")
            return True
        return False

    def _parse(self, path: Path, inp: Input, sink: Sink) -> Robot | None:
        from mpc.backends.formats import reader_of

        suffix = path.suffix.lower()
        if suffix == ".xacro":
            from mpc.backends import xacro_reader

            return xacro_reader.read(path, sink, self.options.resolver, inp.xacro_args, inp.span,
                                     inp.xacro_env)
        read = reader_of(path).read
        assert read is not None
        return read(path, sink, self.options.resolver)

    def _repo_file(self, inp: Input, fetch: bool) -> Path | None:
        from mpc.compiler.repos import checkout

        assert inp.repo is not None
        tree = checkout(inp.repo, self.sink, inp.span, fetch=fetch)
        if tree is None:
            return None
        self.options.resolver.add_root(tree)
        path = tree / inp.repo.model_in_repo
        if not path.is_file():
            self.sink.error(inp.span, "E0601", f"'{inp.repo.model_in_repo}' is not in repository "
                            f"'{inp.repo.git}' at '{inp.repo.commit or inp.repo.branch or 'HEAD'}'")
            return None
        return path

    def report_missing_meshes(self) -> None:
        """`mpc check`: the input models' mesh files that do not exist, reported after the
        names are checked (which they do not hinder)."""
        for missing in self.missing_meshes:
            self.sink.report(missing)

    def names(self, inp: Input) -> Names | None:
        """The input's names, without applying any op that changes geometry."""
        key = self._key(inp)
        if key not in self._names:
            self._names[key] = self._load_names(inp)
        return self._names[key]

    def name_span(self, inp: Input, kind: str, name: str) -> Span | None:
        """Where the input model holds `name` (a link, a pose), when it was read and can tell:
        a link's element; a pose's entry in the annotation files of a SMURF."""
        robot = self._robots.get(self._key(inp))
        if robot is None:
            return None
        if kind == "link" and name in robot.links:
            return robot.links[name].span
        if kind == "pose" and inp.path is not None and inp.path.suffix.lower() == ".smurf":
            from mpc.backends.smurf_reader import entry_span

            return entry_span(inp.path, "poses", name)
        return None

    def _load_names(self, inp: Input) -> Names | None:
        if inp.kind == "derived_base" and self.symbolic:
            assert inp.path is not None
            if self._cycle(inp) or self._refused(inp.path, inp):
                return None
            assert self.names_of is not None, "derived_base inputs need driver.input_loader's loader"
            return self.names_of(inp.path, self.sink, self.options, (*self.stack, inp.path))
        if inp.kind == "repo" and self._repo_file(inp, fetch=False) is None:
            return None  # `mpc check` does not clone; names are checked once it is cached
        robot = self.robot(inp)
        if robot is not None and self.symbolic:
            self.missing_meshes += _missing_meshes(robot, inp.span)
        return Names.of(robot) if robot is not None else None


def _missing_meshes(robot: Robot, where: Span) -> list[Diagnostic]:
    """`mpc check`: the input model's mesh files that do not exist (E0602, as writing them
    would say; E0654 once for a package not found); none is read. Every mesh of the input
    counts, also one a later edit removes. The driver reports them after the names are
    checked, which they do not hinder."""
    seen: set[Path] = set()  # each file is looked for once (most are used by a visual and a collision)
    out = []
    uses = [(name, element, item.geometry) for name, link in robot.links.items()
            for element, items in (("visual", link.visuals), ("collision", link.collisions))
            for item in items if isinstance(item.geometry, Mesh)]
    if any(mesh.source.path is None for _, _, mesh in uses):  # a package not found: once each
        from mpc.backends.missing_packages import unfound_packages

        out += unfound_packages(uses, where)
    for name, element, mesh in uses:
        path = mesh.source.path  # None: its package was not found (reported above)
        if path is not None and path not in seen:
            seen.add(path)
            if not path.is_file():
                out.append(Diagnostic(Severity.ERROR, "E0602", f"mesh file '{path}' of a {element} of "
                                      f"link '{name}' {why_absent(path)}", mesh.span or where))
    return out
