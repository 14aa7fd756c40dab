"""check_exports (`mpc check`): the names inside export entries, on the finished robot's names.

Input: the program and the names check_names found for the finished robot. Output:
diagnostics only. It sees what compiling sees when it writes the exports (ir/submodel.py,
backends/joint_limits.py, backends/kccd.py), with the same codes and messages, but without
building anything: a submodel's `start`, `stop` and `remove_joints`, its
`move_joint_axis_to_intersection`, a `joint_limits` list, and the joints and links a `kccd`
entry names. It does not look inside a submodel's own exports (they name the submodel's
links after its merges and replacements), and whether a joint is movable or a link a KCCD
body, which needs the geometry, is left to compiling.
"""

from __future__ import annotations

from collections.abc import Collection

from mpc.core.diagnostics import Sink, did_you_mean
from mpc.ir.names import Names
from mpc.ir.program import Export, JointLimitsExport, KccdExport, Program, SubmodelExport

SELECTIONS = ("ALL", "ACTIVE", "INDEPENDENT", "ACTUATED", "ABSTRACT")


def check_exports(program: Program, names: Names, sink: Sink) -> None:
    submodels = {e.name for e in program.exports if isinstance(e, SubmodelExport)}
    for export in program.exports:
        if getattr(export, "add_floating_base", False) and not getattr(export, "submodel", "") \
                and export.type != "smurf":  # a SMURF's flag is the one of the model it links
            _floating(export, names.links, names.joints, sink)
        if isinstance(export, SubmodelExport):
            _submodel(export, names, sink)
        elif isinstance(export, JointLimitsExport) and not export.submodel and not export.joints_of:
            if export.joints in ((s,) for s in SELECTIONS) or (
                    len(export.joints) == 1 and export.joints[0] in submodels):
                continue
            for name in export.joints:
                if name not in names.joints:
                    sink.error(export.span, "E0310", f"joint_limits lists '{name}', which is not a "
                               f"movable joint of the model{did_you_mean(name, set(names.joints))}")
        elif isinstance(export, KccdExport) and not export.submodel:
            _kccd(export, names, sink)


def _submodel(export: SubmodelExport, names: Names, sink: Sink) -> None:
    """What ir/submodel.py's `cut` reports, on names: start, stop, remove_joints, moved axes."""
    from mpc.ir.submodel import matching, part_links  # with the ops it imports: only for a submodel

    part = part_links(names, export, sink)
    if part is None:
        return
    kept = part[1]
    joints = {j for j, (p, c) in names.joints.items() if p in kept and c in kept}
    if export.add_floating_base:
        _floating(export, kept, joints, sink)
    gone: set[str] = set()
    for pattern in export.remove_joints:
        found = matching(pattern, joints)
        if not found:
            sink.error(export.span, "E0310", f"submodel '{export.name}': remove_joints '{pattern}' "
                       f"names no joint of the submodel{did_you_mean(pattern, joints)}")
            return
        gone |= found
    if export.remove_fixed or export.abstract_model:  # which joints stay needs their types
        return
    for joint, pair in export.move_joint_axis_to_intersection.items():
        for name in (joint, *pair):
            if name not in joints - gone:
                sink.error(export.span, "E0310", f"submodel '{export.name}': "
                           f"move_joint_axis_to_intersection names '{name}', which is not a joint "
                           f"of the submodel{did_you_mean(name, joints - gone)}")
                return


def _floating(export: Export, links: Collection[str], joints: Collection[str], sink: Sink) -> None:
    """What compiling reports (E0505) of an add_floating_base on a robot with these names."""
    from mpc.ir.floating import FLOATING_HINT, clash

    if why := clash(links, joints):
        sink.error(export.span, "E0505", why, hint=FLOATING_HINT)


def _kccd(export: KccdExport, names: Names, sink: Sink) -> None:
    """What backends/kccd.py reports of the names a kccd entry gives, where names suffice."""
    above = {child: joint for joint, (_, child) in names.joints.items()}
    for key in ("remove_joints", "merge_additionally"):
        for name in getattr(export, key):
            if name not in names.joints:
                hint = f"give the joint above it, '{above[name]}'" if name in above else None
                sink.error(export.span, "E0522", f"kccd {key} names '{name}', which is not a joint of "
                           f"the model{'' if hint else did_you_mean(name, set(names.joints))}", hint=hint)
    named = [("simplify_swept_from", n) for n in export.simplify_swept_from]
    named += [("edit_collisions", n) for n in (*export.n_points, *export.shapes)]
    named += [("no_collision_between", n) for link, others in export.no_collision_between.items()
              for n in (link, *others)]
    for key, name in named:
        if name not in names.links:
            sink.error(export.span, "E0522", f"kccd {key} names '{name}', which is not a link of the "
                       f"model{did_you_mean(name, set(names.links))}")
