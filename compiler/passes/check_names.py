"""check_names: run every op on the input models' *names* and report what is missing.
With an export that makes file names of poses or links, it also reports those names that cannot
be file names, where they were made (check_file_names.py, E0540).

No geometry is read: each part starts from the names of its input model (or nothing
when they cannot be known, e.g. a repo not cloned yet), each op's `reads` are looked
up and its `effect` gives the names after it, attaches merge parts.

    input_models: {arm: {basefile: arm.urdf}}            # links: base, upper, lower
    assemble: {model: arm, take_leaf: uper}
    → error[E0310]: take_leaf refers to unknown link 'uper'; did you mean 'upper'?
"""

from __future__ import annotations

from collections.abc import Callable

from mpc.compiler.passes.context import PassContext
from mpc.core.diagnostics import Severity, did_you_mean
from mpc.ir.names import Names
from mpc.ir.ops import Attach, Effects, LoadModel, Op
from mpc.ir.program import Program

# Called with each op that ran on known names, its part's names before it and after it.
Trace = Callable[[Op, Names, Names], None]


def symbolic(program: Program, ctx: PassContext, trace: Trace | None = None) -> Names | None:
    """The names of the finished robot (None when an input's names are unknown)."""
    parts: dict[str, Names | None] = {}
    origins: dict[str, str] = {}
    unsupported: dict[str, list[Op]] = {}
    for op in program.ops:
        if isinstance(op, LoadModel):
            parts[op.part] = ctx.input_names(program.inputs[op.input])
            origins[op.part] = f"'{op.input}'"
            continue
        names = parts.get(op.part)
        effects = Effects(ctx.sink, op, ctx.later is Severity.ERROR)
        if not type(op).SUPPORTED:
            unsupported.setdefault(op.kind, []).append(op)
        if isinstance(op, Attach):
            child = parts.pop(op.child, None)
            if names is not None and child is not None:
                op = op.resolved(names, child)  # append_link_suffix: NAME_DUPLICATES
            if names is not None and child is not None and _reads_ok(op, names, ctx):
                parts[op.part] = op.merge(names, child, effects,
                                          (origins[op.part], origins.pop(op.child, "?")))
                if trace is not None:  # the parent part's names before the child joins it
                    trace(op, names, parts[op.part])  # type: ignore[arg-type]
            else:
                parts[op.part] = None
            continue
        if names is not None and (_reads_ok(op, names, ctx) or not type(op).EFFECT_NEEDS_READS):
            parts[op.part] = op.effect(names, effects)
            if trace is not None:
                trace(op, names, parts[op.part])
    for kind, ops in unsupported.items():  # once per kind, where it is first used
        uses = f" ({len(ops)} uses)" if len(ops) > 1 else ""
        Effects(ctx.sink, ops[0], ctx.later is Severity.ERROR).unsupported(f"the {kind} operation{uses}")
    return parts.get("root")


def _reads_ok(op: Op, names: Names, ctx: PassContext) -> bool:
    ok = True
    for ref in op.reads():
        pool = names.all(ref.kind)
        if ref.name not in pool and ref.name in names.gone:
            ctx.sink.error(op.span_of(ref.field), "E0310",
                           f"{op.what()} refers to {ref.kind} '{ref.name}', which "
                           f"{names.gone[ref.name]} removed")
            ok = False
        elif ref.name not in pool:
            what = op.what()
            shown = (f"'{ref.written}' ('{ref.name}' after name editing)" if ref.written
                     else f"'{ref.name}'")
            ctx.sink.error(op.span_of(ref.field), "E0310",
                           f"{what} refers to unknown {ref.kind} {shown}"
                           f"{did_you_mean(ref.name, pool)}",
                           hint=_nearest_first(ref.name, pool))
            ok = False
    return ok


def _nearest_first(name: str, pool: frozenset[str], shown: int = 8) -> str | None:
    """The names there are, nearest to `name` first."""
    if not pool:
        return None
    from difflib import SequenceMatcher

    ranked = sorted(pool, key=lambda n: (-SequenceMatcher(None, name, n).ratio(), n))
    more = f" and {len(pool) - shown} more" if len(pool) > shown else ""
    return "there are: " + ", ".join(ranked[:shown]) + more


def check_names(program: Program, ctx: PassContext) -> Program:
    from mpc.compiler.passes.check_file_names import Origins, check_file_names, file_routes

    origins = Origins(file_routes(program))
    names = symbolic(program, ctx, origins.trace if origins.kinds else None)
    if names is not None and origins.kinds:
        check_file_names(program, names, origins, ctx.input_names, ctx.name_span,
                         lambda span, message: ctx.sink.error(span, "E0540", message))
    # the exports' names, once the rest is right: on names every op could edit, and not after
    # lowering reported an export's problem (it would be said twice)
    if names is not None and not ctx.sink.has_errors() and ctx.later is Severity.WARNING:
        from mpc.compiler.passes.check_exports import check_exports  # `mpc check` only

        check_exports(program, names, ctx.sink)
    return program
