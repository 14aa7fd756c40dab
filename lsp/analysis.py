"""One buffer of a definition or pipeline file → `mpc check`'s diagnostics, and what the editor
features ask about it: the names before each op, where names are written, the input robots.

The check is `mpc check`'s (compiler/front_end.py's front end and passes, pipeline/plan.py's
check_pipeline), run on the editor's text of every open file (core/yaml_source.py `overlay`),
with input models from the server's ModelCache (compiler/inputs.py): a keystroke re-reads no
model file. What this does not do: talk LSP (server.py), or build outputs.
"""

from __future__ import annotations

import os
from dataclasses import field, replace
from pathlib import Path

from mpc.compiler import front_end, ops_run
from mpc.compiler.inputs import InputLoader
from mpc.compiler.options import Options
from mpc.compiler.passes import PassContext, run_passes
from mpc.compiler.passes.check_names import symbolic
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.files import describe, resolved
from mpc.core.packages import PackageResolver
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.names import Names
from mpc.ir.ops import Attach, LoadModel, Op
from mpc.ir.program import Program
from mpc.ir.refs import refs
from mpc.ir.robot import Robot

# backends/xacro_origins.py's answers, by (file, xacro args, modification time, size)
_ORIGINS: dict[tuple[str, tuple[tuple[str, str], ...], int, int], dict[int, tuple[str, Span]]] = {}


@record
class Step:
    """An op that ran on known names, with its part's names before and after it (and, for an
    attach, the child part's names as it joins)."""

    op: Op
    before: Names
    after: Names
    child: Names | None = None


@record
class Site:
    """A link, joint or other name written in the definition, and what it names."""

    kinds: tuple[str, ...]
    span: Span
    defines: bool


@record(frozen=False)
class Analysis:
    """What one check of a buffer found.

    program: as lowered (its ops carry the spans of what they name); None when the
    definition did not get that far. passed: after the passes; ran: the same, when they found
    no error. steps(): the ops in the order they run, on names (worked out when asked).
    inputs: the robots of the input models read from files, by input name.
    depends: the YAML files the check read (defaults chain, derived_base definitions).
    """

    path: Path
    text: str
    diagnostics: list[Diagnostic]
    pipeline: bool = False
    doc: source.Document | None = None
    program: Program | None = None
    inputs: dict[str, Robot] = field(default_factory=dict)
    depends: set[str] = field(default_factory=set)
    sites: list[Site] = field(default_factory=list)
    passed: Program | None = None
    ran: Program | None = None
    loader: InputLoader | None = None
    _built: Robot | None = None
    _steps: list[Step] | None = None

    def steps(self) -> list[Step]:
        """Each op that ran on known names, in the order they run, with the names around it."""
        if self._steps is None:
            steps: list[Step] = []
            if self.passed is not None and self.loader is not None:
                program, names = self.passed, self.loader.names
                parts = {op.part: names(program.inputs[op.input])
                         for op in program.ops if isinstance(op, LoadModel)}

                def trace(op: Op, before: Names, after: Names) -> None:
                    child = parts.get(op.child) if isinstance(op, Attach) else None
                    parts[op.part] = after
                    steps.append(Step(op, before, after, child))

                symbolic(program, PassContext(Sink(), names, Severity.WARNING), trace)
            self._steps = steps
        return self._steps

    def names_at(self, line: int, col: int, indent: int, child: bool = False) -> Names | None:
        """The names of the robot where the cursor is (1-based line, col; `indent` of its line):
        before the op whose entry holds the cursor, else after the last op written above it.
        Ops written in other files (a defaults file) count where they run, not where they are.
        `child`: in a child's `joint`, the child part's names (those of its `child` link)."""
        steps = self.steps()
        here = [s for s in steps if s.op.span.file == str(self.path)]
        if not here:
            return steps[-1].after if steps else None

        def where(step: Step) -> tuple[int, int]:
            return step.op.span.line, step.op.span.col

        above = [s for s in here if where(s) <= (line, col)]
        if not above:
            return min(here, key=where).before
        nearest = max(above, key=where)
        inside = nearest.op.span.line == line or nearest.op.span.col - 1 < indent
        if inside and child and nearest.child is not None:
            return nearest.child
        return nearest.before if inside else nearest.after

    def xacro_origins(self, path: Path) -> dict[int, tuple[str, Span]]:
        """Where the links and joints of the xacro input model at `path` are written, by their
        line in its expansion (backends/xacro_origins.py). Expanded when first asked, then kept
        while the file's modification time and size stay (as ModelCache keeps the model)."""
        absolute = os.path.abspath(path)
        inputs = self.program.inputs.values() if self.program is not None else ()
        args = next((inp.xacro_args for inp in inputs
                     if inp.path is not None and os.path.abspath(inp.path) == absolute), ())
        try:
            stat = os.stat(absolute)
        except OSError:
            return {}
        key = (absolute, args, stat.st_mtime_ns, stat.st_size)
        if key not in _ORIGINS:
            # imported here: xml.dom.minidom and the rest are for go to definition in xacro only
            from mpc.backends.xacro_origins import origins

            resolver = self.loader.options.resolver if self.loader is not None else PackageResolver()
            while len(_ORIGINS) >= 8:
                del _ORIGINS[next(iter(_ORIGINS))]
            _ORIGINS[key] = origins(path, resolver, args)
        return _ORIGINS[key]

    def readers(self) -> dict[str, Span]:
        """The span of this buffer that reads each input model file, by absolute path."""
        if self.program is None:
            return {}
        return {os.path.abspath(inp.path): inp.span for inp in self.program.inputs.values()
                if inp.path is not None and os.path.abspath(inp.span.file) == os.path.abspath(self.path)}

    def built(self) -> Robot | None:
        """The robot the definition describes (its ops applied), built once when asked."""
        if self._built is None and self.ran is not None and self.loader is not None:
            sink = Sink()
            self._built = ops_run.apply(self.ran, sink, replace(self.loader, sink=sink))
        return self._built


def analyse(path: Path, text: str, open_texts: dict[str, str], options: Options) -> Analysis:
    """Check the buffer `text` of the file `path` as `mpc check` checks that file."""
    sink = Sink()
    analysis = Analysis(path, text, sink.diagnostics)
    with source.overlay(open_texts) as loaded:
        try:
            analysis.doc = doc = source.loads(text, str(path), sink, fast=True)
            if doc is None:
                return analysis
            if isinstance(doc.data, dict) and "pipeline" in doc.data:
                analysis.pipeline = True
                from mpc.pipeline.plan import check_pipeline_file

                check_pipeline_file(path, sink, options)
            else:
                _check_definition(analysis, doc, sink, options)
        except OSError as e:
            sink.error(Span.of_file(str(path)), "E0661", describe(e, "read an input of the model"))
        finally:
            analysis.depends = loaded - {str(path)}
    return analysis


def _check_definition(analysis: Analysis, doc: source.Document, sink: Sink, options: Options) -> None:
    """The front end and passes of front_end.front_end, keeping the program and the names per op."""
    path = analysis.path
    loader = front_end.input_loader(sink, options, (resolved(path),), symbolic=True)
    lowered = front_end.front_end(path, sink, options, Severity.WARNING, loader, doc=doc, passes=False)
    if lowered is None:
        return
    analysis.program, analysis.loader = lowered, loader
    errors = sink.error_count
    program = run_passes(lowered, PassContext(sink, loader.names, Severity.WARNING,
                                                      loader.name_span))
    analysis.passed = program
    if sink.error_count == errors:
        analysis.ran = program  # a missing mesh file (below) does not keep hover from the robot
    loader.report_missing_meshes()
    for name, inp in lowered.inputs.items():
        if inp.kind != "derived_base":
            robot = loader.robot(inp) if inp.kind == "basefile" else None
            if robot is not None:
                analysis.inputs[name] = robot
    for op in lowered.ops:
        for declared, _, where in refs(op):
            if where in op.spans:
                analysis.sites.append(Site(declared.kinds, op.spans[where], declared.defines))
