"""fold_renames: consecutive name edits of one part become one `edit_names`.

Input: an ordered Program. Output: the program with each run of foldable `edit_names` ops
replaced by one op whose rules are theirs in order, and `edit_names` that change nothing
removed. What it does not do: fold across another op, or fold edits that `only` rename some
names, or whose order of rules one op cannot keep.

Two edits fold when they are of one part and one phase, edit the same kinds of names, rename
every name of those kinds (no `only`), the first has no flag (`joint_equals_link_name` and
`append_link_suffix` act on the result of the rules, so only the last may have them), and the
first has no rule of one kind that the second's rules for every kind would have to follow
(`edit_name` applies the rules for every kind before those of one kind).

    op edit_names rules=[NameRule(prefix="l_")] @ a.ir:3
    op edit_names rules=[NameRule(suffix="_1")] @ a.ir:4
    → op edit_names rules=[NameRule(prefix="l_"), NameRule(suffix="_1")] @ a.ir:3
"""

from __future__ import annotations

from dataclasses import replace

from mpc.compiler.passes.context import PassContext
from mpc.ir.ops import EditNames, Op
from mpc.ir.program import Program


def _foldable(a: Op, b: Op) -> bool:
    """Whether `b` right after `a` is one edit with their rules in order."""
    if not (isinstance(a, EditNames) and isinstance(b, EditNames)):
        return False
    if a.part != b.part or a.phase() != b.phase() or a.kinds != b.kinds or a.only or b.only:
        return False
    if a.joint_equals_link_name or a.append_link_suffix:
        return False
    scoped_first = any(rule.scope != "all" for rule in a.rules)
    return not (scoped_first and any(rule.scope == "all" for rule in b.rules))


def _does_nothing(op: Op) -> bool:
    return (isinstance(op, EditNames) and not op.rules and not op.only
            and not op.joint_equals_link_name and not op.append_link_suffix)


def fold_renames(program: Program, ctx: PassContext) -> Program:
    folded: list[Op] = []
    for op in program.ops:
        if _does_nothing(op):
            continue
        first = folded[-1] if folded else None
        if first is not None and _foldable(first, op):
            assert isinstance(first, EditNames) and isinstance(op, EditNames)
            folded[-1] = replace(first, rules=first.rules + op.rules,
                                 joint_equals_link_name=op.joint_equals_link_name,
                                 append_link_suffix=op.append_link_suffix)
            continue
        folded.append(op)
    return program if len(folded) == len(program.ops) else replace(program, ops=tuple(folded))
