"""AST → ir.Program: inputs resolved to files, ops in the order the language fixes.

Lowering reads no input model. Each section has its module, which returns its ops or exports
(it shares no list with the others): compiler/lower_inputs.py (`input_models`),
lower_assembly.py (`assemble`: for each part depth first, load, name editing, remove_beyond,
take_leaf, mirror, then its children, then the attach to its parent), lower_edits.py (the
editing sections, in the order of its EDIT_STEPS), lower_exports.py (`export_config`,
`post_processing`), lower_model_tests.py (`test`)… This module puts them together, in the order of the
phases (ir/ops/base.py: Phase), which compiler/passes/order_ops.py checks again. Parts of the
language that later versions will lower are reported through `later` (an error for
`compile`, a warning for `check`).
"""

from __future__ import annotations

from pathlib import Path

from mpc.compiler.lower_assembly import lower_assembly
from mpc.compiler.lower_context import LowerContext
from mpc.compiler.lower_deploy import lower_model_deployment
from mpc.compiler.lower_edits import lower_edits
from mpc.compiler.lower_exports import lower_exports
from mpc.compiler.lower_inputs import lower_inputs
from mpc.compiler.schema import Definition
from mpc.core.diagnostics import Severity, Sink
from mpc.core.packages import PackageResolver
from mpc.ir.ops import SetRobotName
from mpc.ir.program import Input, Program

# Sections of the model that later versions lower; named here so that nothing is ignored.
LATER_SECTIONS = ("swing_my_robot",)


def lower(ast: Definition, base_dir: Path, sink: Sink, resolver: PackageResolver,
          later: Severity = Severity.ERROR) -> Program:
    """The program of a validated definition file in `base_dir`, also after errors (values
    that failed are None), so that the names in it can still be checked; the errors stop the
    build later."""
    ctx = LowerContext(ast.model, base_dir, sink, resolver, later)
    model = ctx.model
    inputs = lower_inputs(ctx)
    ops = [*lower_assembly(ctx, inputs),
           SetRobotName(span=model.value_span("robotname"), name=model.robotname),
           *lower_edits(ctx)]
    _report_unused(ctx, inputs)
    exports = lower_exports(ctx)
    test = None
    if model.test is not None:
        from mpc.compiler.lower_model_tests import lower_test

        test = lower_test(model.test, base_dir, sink)
    return Program(robotname=model.robotname, modelname=model.modelname, inputs=inputs, ops=tuple(ops),
                   exports=exports, span=model.span, test=test,
                   deployment=lower_model_deployment(model, sink))


def _report_unused(ctx: LowerContext, inputs: dict[str, Input]) -> None:
    """What the definition says that compiling does not do (yet, or at all here)."""
    model = ctx.model
    for key in LATER_SECTIONS:
        if getattr(model, key):
            ctx.not_yet(model.key_span(key), f"'{key}'")
    if not model.inherit_smurf_properties and not any(i.kind == "derived_base" for i in inputs.values()):
        ctx.sink.warning(model.key_span("inherit_smurf_properties"), "W0531",
                         "'inherit_smurf_properties: false' has no effect: no input model is a "
                         "derived_base", hint="it drops the SMURF data of derived_base inputs")
    for name, entry in model.input_models.items():
        if entry.is_human:
            ctx.not_yet(entry.key_span("is_human"), f"'is_human' (input model '{name}')")
