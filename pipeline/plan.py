"""pipeline.yml → the plan of a run: the settings, the folders, and each model's definition
(after its defaults chain and the pipeline's defaults) with its derived_base edges.

Only YAML is read here: no input model, no lowering, so planning stays fast enough for a
no-op run. Problems of one model (a missing file, a cycle, a clashing modelname) are kept
with that model, which then fails without stopping the others.
"""

from __future__ import annotations

import itertools
import os
import re
from collections.abc import Callable
from dataclasses import field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mpc.compiler import inherit
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Diagnostic, Severity, Sink
from mpc.core.files import input_problem, project_root, resolved, why_absent
from mpc.core.record import record
from mpc.core.span import Span
from mpc.core.yaml_source import Document
from mpc.pipeline import dag, verdicts
from mpc.pipeline.defaults import PipelineDefaults

if TYPE_CHECKING:
    from mpc.compiler.options import Options
    from mpc.compiler.schema.definition import PipelineSection


@record(frozen=False)
class PlannedModel:
    """One entry of `model_definitions`.

    name: its modelname (the output folder's name); the file's stem when it has none.
    definition: the definition file (absolute). written: the path as the pipeline writes it.
    span: that entry in pipeline.yml. data: the definition after its defaults chain and the
    pipeline's defaults (None when it could not be loaded). parents: the names of the
    pipeline's models it takes as derived_base. diagnostics: what planning found.
    """

    name: str
    definition: Path
    written: str
    span: Span
    data: Any = None
    parents: tuple[str, ...] = ()
    parent_spans: dict[str, Span] = field(default_factory=dict)
    diagnostics: list[Diagnostic] = field(default_factory=list)

    @property
    def failed(self) -> bool:
        return any(d.severity is Severity.ERROR for d in self.diagnostics)


@record(frozen=False)
class Plan:
    """A loaded pipeline file: its path, document, settings (the `pipeline` mapping as
    written), the workspace root and the models in the file's order; `section`, the
    settings validated, is made when first asked for (a run where all is cached never
    imports the schema)."""

    file: Path
    doc: Document
    settings: dict[str, Any]
    root: Path
    models: dict[str, PlannedModel]

    @cached_property
    def section(self) -> PipelineSection | None:
        from mpc.compiler import schema

        pipeline = schema.validate_pipeline(self.doc, Sink())  # valid: load_plan checked it
        return pipeline.pipeline if pipeline is not None else None

    @property
    def defaults(self) -> PipelineDefaults:
        return PipelineDefaults(self.doc)

    def parents(self) -> dict[str, tuple[str, ...]]:
        return {name: m.parents for name, m in self.models.items()}


def load_plan(path: Path, sink: Sink, root_outside: Severity | None = Severity.ERROR) -> Plan | None:
    """The plan of the pipeline file at `path`; None (errors in `sink`) when the file itself
    is unusable. Problems of single models stay with those models.

    root_outside: what a `root` outside the pipeline file's folder (and not its parent, the
    default `..`) is: an error (E0621: `mpc run` would write `<root>/build` there), a warning
    (W0624, `mpc check`), or allowed (None: `--allow-root-outside`)."""
    doc = source.load(path, sink)
    if doc is None or not verdicts.valid_pipeline(doc, sink):
        return None
    settings = doc.data["pipeline"]
    # Relative to the pipeline file, never to the working directory (Phobos: the CWD).
    expanded = os.path.expandvars(settings.get("root", ".."))
    root = resolved(resolved(path).parent / expanded)  # a NUL byte stopped source.load (E0106)
    if not root.is_dir():
        problem = "is not a folder" if root.exists() else "does not exist"
        unset = re.findall(r"\$\{?(\w+)", expanded)
        hint = (f"the environment variable {unset[0]} is not set" if unset
                else "`root` is relative to the folder of the pipeline file")
        sink.error(doc.value_span(("pipeline", "root")), "E0640",
                   f"the workspace root '{root}' {problem}",
                   hint=hint)
        return None
    if root_outside is not None and not _root_allowed(root, path.resolve().parent):
        say = sink.error if root_outside is Severity.ERROR else sink.warning
        say(doc.value_span(("pipeline", "root")), "E0621" if root_outside is Severity.ERROR else "W0624",
            f"the workspace root '{root}' is outside the pipeline file's folder "
            f"'{path.resolve().parent}' and its parent; `mpc run` would write '{root / 'build'}'",
            hint="give --allow-root-outside when this root is meant")
        if root_outside is Severity.ERROR:
            return None
    defaults = PipelineDefaults(doc)
    by_file: dict[Path, PlannedModel] = {}
    derived: dict[Path, list[tuple[Path, Span]]] = {}
    for i, written in enumerate(settings["model_definitions"]):
        span = doc.value_span(("pipeline", "model_definitions", i))
        definition = resolved(resolved(path).parent / written)
        if definition in by_file:
            sink.warning(span, "W0611", f"model definition '{written}' is listed twice; it is built once",
                         notes=((by_file[definition].span, "first listed here"),))
            continue
        model, parents = _load_model(path, root, written, definition, span, defaults)
        by_file[definition] = model
        derived[definition] = parents
    _link(by_file, derived)
    models: dict[str, PlannedModel] = {}
    for model in by_file.values():
        _check_name(model, models)
        models.setdefault(model.name, model)
    _break_cycles(models)
    return Plan(path, doc, settings, root, models)


def _root_allowed(root: Path, folder: Path) -> bool:
    """Whether `root` (resolved) is the pipeline file's folder, inside it, or its parent (the
    default `..`: a pipeline kept in a folder of the project, as Phobos CI keeps it)."""
    return root == folder.parent or root == folder or folder in root.parents


# What `mpc check pipeline.yml` reports of planning; checking each definition reports the
# rest (its own errors, cycles as E0308).
_WHOLE_PIPELINE = ("E0601", "E0610", "E0612", "E0641", "E0650", "W0610")


def check_pipeline(path: Path, sink: Sink,
                   check_definition: Callable[[Path, PipelineDefaults], None]) -> None:
    """`mpc check pipeline.yml`: the file itself, what only the whole pipeline shows (clashing
    modelnames, names that cannot be folders, definitions that are missing, listed twice or
    outside the root, derived_base parents outside the pipeline), and each definition that
    can be read, through `check_definition` with the pipeline's defaults."""
    plan = load_plan(path, sink, Severity.WARNING)
    for model in plan.models.values() if plan else ():
        for d in model.diagnostics:
            if d.code in _WHOLE_PIPELINE:
                sink.report(d)
        if not any(d.code in ("E0601", "E0641", "E0650") for d in model.diagnostics):
            check_definition(model.definition, plan.defaults)  # type: ignore[union-attr]


def check_pipeline_file(path: Path, sink: Sink, options: Options) -> None:
    """`mpc check pipeline.yml` with the driver: each definition under the pipeline's defaults."""
    from mpc.compiler import front_end

    # The pipeline's project (its git work tree, else its folder) is every definition's too,
    # as `mpc run` reads them.
    options.resolver.add_project(project_root(path.parent))
    check_pipeline(path, sink, lambda model, defaults: front_end.check_file(
        model, sink, replace(options, defaults=defaults)))


def _load_model(pipeline: Path, root: Path, written: str, definition: Path, span: Span,
                defaults: PipelineDefaults) -> tuple[PlannedModel, list[tuple[Path, Span]]]:
    """One definition, with its defaults applied, and the derived_base files it names."""
    sink = Sink()
    model = PlannedModel(Path(written).stem, definition, written, span)
    display = os.path.normpath(os.path.join(os.path.dirname(str(pipeline)), written))
    if not definition.is_relative_to(root):
        # Its build could not be found again from a clone elsewhere, nor kept by CI.
        sink.error(span, "E0641", f"model definition '{written}' is outside the workspace root '{root}'",
                   hint="set the pipeline's `root` to a folder that holds every model definition")
    else:
        try:
            if definition.is_dir():
                sink.error(span, "E0601", f"model definition '{written}' is a folder, not a file")
            elif not definition.is_file():
                sink.error(span, "E0601", f"model definition '{written}' {why_absent(definition)}")
            elif why := input_problem(definition, (root,)):
                sink.error(span, "E0650", f"model definition '{written}' is not read: {why}")
        except OSError as e:  # a name too long, a loop of links
            sink.error(span, "E0601", f"model definition '{written}' cannot be read: {e.strerror}")
    if sink.diagnostics:
        model.diagnostics = sink.diagnostics
        return model, []
    doc = source.load(definition, sink, display=display, origin=span)
    doc = inherit.resolve(doc, definition, sink) if doc is not None else None
    if doc is not None:
        doc = defaults(doc)
        model.data = doc.data
    model.diagnostics = sink.diagnostics
    spec = doc.data.get("model") if doc is not None and isinstance(doc.data, dict) else None
    if not isinstance(spec, dict):
        return model, []
    if isinstance(spec.get("modelname"), str) and spec["modelname"]:
        model.name = spec["modelname"]
    parents = []
    inputs = spec.get("input_models")
    for key, entry in (inputs.items() if isinstance(inputs, dict) else ()):
        if isinstance(entry, dict) and isinstance(entry.get("derived_base"), str):
            at = doc.value_span(("model", "input_models", key, "derived_base"))
            # Relative to the file that wrote it (a defaults file, or the definition).
            folder = resolved(at.file).parent if at.file else definition.parent
            parents.append((resolved(folder / entry["derived_base"]), at))
    return model, parents


def _link(by_file: dict[Path, PlannedModel], derived: dict[Path, list[tuple[Path, Span]]]) -> None:
    """Turn derived_base files into edges between models; warn about parents outside the pipeline."""
    for definition, parents in derived.items():
        model = by_file[definition]
        names = []
        for parent, at in parents:
            if parent in by_file:
                names.append(by_file[parent].name)
                model.parent_spans.setdefault(by_file[parent].name, at)
            else:
                model.diagnostics.append(Diagnostic(
                    Severity.WARNING, "W0610", f"derived_base '{parent.name}' is not one of the pipeline's "
                    "model_definitions; it is compiled in memory for this model but not built on its own",
                    at))
        model.parents = tuple(dict.fromkeys(names))


def _check_name(model: PlannedModel, seen: dict[str, PlannedModel]) -> None:
    name = model.name
    if name in seen:
        model.diagnostics.append(Diagnostic(
            Severity.ERROR, "E0610", f"model definitions '{seen[name].written}' and '{model.written}' "
            f"both build model '{name}'", model.span, notes=((seen[name].span, "the other one"),),
            hint="give each definition its own modelname"))
        model.name = f"{name} ({model.written})"  # kept apart so its status can be reported
    elif name in (".", "..") or "/" in name or "\\" in name or name.startswith("."):
        model.diagnostics.append(Diagnostic(
            Severity.ERROR, "E0612", f"modelname '{name}' cannot name an output folder", model.span,
            hint="a modelname is a folder name: no '/', and not starting with '.'"))


def _break_cycles(models: dict[str, PlannedModel]) -> None:
    """Fail every model on a derived_base cycle, naming the loop; the edges stay, so the
    models that depend on the cycle are skipped."""
    for loop in dag.cycles({n: m.parents for n, m in models.items()}):
        text = " → ".join(models[n].written for n in loop)
        for name, parent in itertools.pairwise(loop):
            model = models[name]
            model.diagnostics.append(Diagnostic(
                Severity.ERROR, "E0611", f"derived_base cycle: {text}",
                model.parent_spans.get(parent, model.span)))
