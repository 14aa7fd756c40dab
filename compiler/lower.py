"""AST → ir.Program: inputs resolved to files, ops in the order the language fixes.

Lowering does not read input models; it only checks what the definition alone
can tell (that `assemble.model` names an input model).
"""

from __future__ import annotations

from pathlib import Path

from mpc.backends.packages import PackageResolver
from mpc.compiler.diagnostics import Sink, did_you_mean
from mpc.compiler.schema import Definition
from mpc.ir.ops import SetRobotName
from mpc.ir.program import Input, Program, UrdfExport

DEFAULT_EXPORTS = ({"type": "urdf", "mesh_format": "input_type"},)


def resolve_file(written: str, base_dir: Path, resolver: PackageResolver) -> Path:
    """A file named in a definition: `package://…`, absolute, or relative to its folder."""
    if written.startswith("package://"):
        source = resolver.resolve(written, base_dir)
        if source.path is not None:
            return source.path
    return (base_dir / written).resolve()


def lower(ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver) -> Program | None:
    """The program of a validated definition file in `base_dir`."""
    model = ast.model
    inputs = {
        name: Input(name=name, kind="basefile",
                    path=resolve_file(entry.basefile, base_dir, resolver),
                    span=entry.value_span("basefile"))
        for name, entry in model.input_models.items()
    }
    if model.assemble.model not in inputs:
        sink.error(model.assemble.value_span("model"), "E0301",
                   f"assemble.model '{model.assemble.model}' is not one of the input models "
                   f"({', '.join(sorted(inputs))}){did_you_mean(model.assemble.model, set(inputs))}")
        return None
    if model.export_config is None:
        exports = (UrdfExport(mesh_format="input_type", span=model.span),)
    else:
        exports = tuple(UrdfExport(mesh_format=e.mesh_format, span=e.span)
                        for e in model.export_config)
    ops = (SetRobotName(name=model.robotname, span=model.value_span("robotname")),)
    return Program(robotname=model.robotname, modelname=model.modelname, inputs=inputs,
                   base=model.assemble.model, ops=ops, exports=exports, span=model.span)
