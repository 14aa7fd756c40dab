"""Input models, loaded once per compilation: the robot of a file, of another definition's
output (`derived_base`), or of a file in a git repository (`repo`); or just their names.

A `derived_base` is compiled in memory (its front end and ops, no emission); a cycle
of derived_base definitions is a diagnostic naming the loop.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from mpc.compiler.options import Options
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.files import why_absent
from mpc.core.span import Span
from mpc.ir.geometry import Mesh
from mpc.ir.names import Names
from mpc.ir.program import Input
from mpc.ir.robot import Robot

# How a derived_base definition is built, or its names found (compiler/front_end.py's `build`
# and `names_of`, handed to the loader so that loading inputs does not import the front end).
Build = Callable[[Path, Sink, Options, tuple[Path, ...]], Robot | None]
FindNames = Callable[[Path, Sink, Options, tuple[Path, ...]], Names | None]


@dataclass
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
        for definition in self.stack:  # inputs may link to files beside their definitions
            self.options.resolver.add_root(definition.parent)

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

    def _load(self, inp: Input) -> Robot | None:
        if inp.kind == "basefile":
            if inp.path is None:  # its package was not found; reported when lowering
                return None
            return self._read(inp.path, inp)
        if inp.kind == "derived_base":
            assert inp.path is not None
            if self._cycle(inp):
                return None
            assert self.build is not None, "derived_base inputs need driver.input_loader's loader"
            return self.build(inp.path, self.sink, self.options, (*self.stack, inp.path))
        path = self._repo_file(inp, fetch=True)
        return None if path is None else self._read(path, inp)

    def _read(self, path: Path, inp: Input) -> Robot | None:
        """A model file, by its extension: URDF, SDF, SMURF, or a xacro (expanded with its args)."""
        if why := self.options.resolver.refusal(path):
            self.sink.error(inp.span, "E0650", f"input model '{path}' is not read: {why}")
            return None
        if self.options.models is not None:
            return self.options.models.read(path, inp.xacro_args, self.sink,
                                            lambda sink: self._parse(path, inp, sink))
        return self._parse(path, inp, self.sink)

    def _parse(self, path: Path, inp: Input, sink: Sink) -> Robot | None:
        from mpc.backends import BACKENDS

        suffix = path.suffix.lower()
        if suffix == ".xacro":
            from mpc.backends import xacro_reader

            return xacro_reader.read(path, sink, self.options.resolver, inp.xacro_args, inp.span)
        reader = BACKENDS[suffix[1:] if suffix in (".sdf", ".smurf") else "urdf"]()
        return reader.read(path, sink, self.options.resolver)

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

    def _load_names(self, inp: Input) -> Names | None:
        if inp.kind == "derived_base" and self.symbolic:
            assert inp.path is not None
            if self._cycle(inp):
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
    would say); none is read. Every mesh of the input counts, also one a later edit removes.
    The driver reports them after the names are checked, which they do not hinder."""
    seen: set[Path] = set()
    out = []
    for name, link in robot.links.items():
        for element, items in (("visual", link.visuals), ("collision", link.collisions)):
            for item in items:
                mesh = item.geometry
                if not isinstance(mesh, Mesh):
                    continue
                src, span = mesh.source, mesh.span or where
                if src.path is None:
                    out.append(Diagnostic(
                        Severity.ERROR, "E0602", f"mesh '{src.uri}' of a {element} of link '{name}' "
                        f"cannot be found: {src.unresolved}", span,
                        hint="map the package with --package NAME=DIR or ROS_PACKAGE_PATH"))
                elif src.path not in seen and not src.path.is_file():
                    out.append(Diagnostic(Severity.ERROR, "E0602", f"mesh file '{src.path}' of a "
                                          f"{element} of link '{name}' {why_absent(src.path)}", span))
                    seen.add(src.path)
    return out
