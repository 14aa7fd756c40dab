"""Tests that the build did what the definition asked: process_double_check (every operation
left its mark on the written model) and file_consistency (no file of the compare model lost)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from mpc.checks.protocol import Result, failed, first_of, passed, skipped
from mpc.checks.registry import Context, register
from mpc.ir.geometry import Mesh
from mpc.ir.ops import AddCutJoint, EditJoint, RemoveJoint, SetMotor, SetRobotName
from mpc.ir.ops.frames import AddFrame
from mpc.ir.program import ModelTest
from mpc.ir.robot import Robot

_LIMITS = (("lower", "lower"), ("upper", "upper"), ("effort", "effort"), ("velocity", "velocity"))
_DYNAMICS = (("damping", "damping"), ("friction", "friction"))


def _close(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def op_marks(ops: Sequence[object], built: Robot, robot: Robot) -> tuple[list[str], int]:
    """Problems with the marks the ops should have left on the written model `built` (with
    the cut joints and motors the definition lends it), and how many marks were checked.
    `robot` is the definition applied.

    A name an op used may have been renamed or removed by a later op; such a mark is not
    looked for (the names of the whole model are compared separately)."""
    problems: list[str] = []
    checked = 0
    last_edit: dict[str, EditJoint] = {}
    for op in ops:
        if isinstance(op, EditJoint):
            last_edit[op.joint] = op
        elif isinstance(op, RemoveJoint) and op.joint not in robot.joints:
            checked += 1
            if op.joint in built.joints:
                problems.append(f"joint '{op.joint}' was to be removed, but the model has it")
        elif isinstance(op, SetRobotName):
            checked += 1
            if built.name != op.name:
                problems.append(f"the robot is named '{built.name}', not '{op.name}'")
        elif isinstance(op, AddCutJoint) and op.joint not in robot.joints:
            checked += 1
            if op.joint not in built.cut_joints:
                problems.append(f"cut joint '{op.joint}' is missing")
        elif isinstance(op, SetMotor) and op.joint in robot.joints:
            checked += 1
            if not any(m.joint == op.joint for m in built.motors.values()):
                problems.append(f"joint '{op.joint}' has no motor")
        elif isinstance(op, AddFrame) and op.link in robot.links:
            checked += 1
            if op.link not in built.links:
                problems.append(f"frame '{op.link}' is missing")
    for name, op in sorted(last_edit.items()):
        if name not in robot.joints:
            continue
        joint = built.joints.get(name)
        if joint is None:
            problems.append(f"joint '{name}' was edited but is not in the model")
            continue
        checked += 1
        if op.type is not None and joint.type != op.type:
            problems.append(f"joint '{name}' is {joint.type}, the definition sets {op.type}")
        for group, pairs in ((joint.limit, _LIMITS), (joint.dynamics, _DYNAMICS)):
            for key, attr in pairs:
                want = getattr(op.values, key)
                have = getattr(group, attr) if group is not None else None
                if want is not None and not _close(want, have):
                    problems.append(f"joint '{name}' has {key} {have}, the definition sets {want:g}")
    return problems, checked


def _mesh_problems(built: Robot) -> list[str]:
    problems = []
    for link in sorted(built.links.values(), key=lambda x: x.name):
        for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
            for shape in shapes:
                if isinstance(shape.geometry, Mesh):
                    src = shape.geometry.source
                    if src.path is None or not src.path.is_file():
                        problems.append(f"{kind} mesh '{src.uri}' of link '{link.name}' does not exist")
    return problems


@register("process_double_check")
def process_double_check(ctx: Context, test: ModelTest) -> Result:
    """The written model has exactly the links and joints the definition produces, every
    operation's mark (removed joints absent, set limits and types present, the robot's name,
    frames, cut joints, motors), and every mesh file it references."""
    built = ctx.built.robot
    problems = _mesh_problems(built)
    checked = 0
    if ctx.robot is not None:
        robot = ctx.robot
        for kind, want, have in (("link", robot.links, built.links), ("joint", robot.joints, built.joints)):
            problems += [f"{kind} '{n}' of the definition is missing" for n in sorted(set(want) - set(have))]
            problems += [f"{kind} '{n}' is not in the definition" for n in sorted(set(have) - set(want))]
        marks, checked = op_marks(ctx.program.ops, built, robot)
        problems += marks
    reason = f"{checked} operations checked, {len(built.links)} links, {len(built.joints)} joints, mesh files"
    if ctx.robot is None:
        reason += " (the definition could not be applied: only mesh files checked)"
    if problems:
        return failed(test.name, first_of(problems),
                      figure=float(len(problems)), unit="problems", details=tuple(problems))
    return passed(test.name, reason, figure=0.0, unit="problems")


# Files a model output does not need to keep (Phobos's list, plus mpc's protocols).
_IGNORED = re.compile(r"(^|/)(\.git|README\.md$|manifest\.xml$|meshes/|test_protocol\.)|\.gv$|\.pdf$")


def _files(folder: Path) -> set[str]:
    out = set()
    for p in folder.rglob("*"):
        rel = p.relative_to(folder).as_posix()
        if p.is_file() and not _IGNORED.search(rel):
            out.add(rel)
    return out


@register("file_consistency", needs="both")
def file_consistency(ctx: Context, test: ModelTest) -> Result:
    """No file of the compare model's folder is missing from the output (meshes, PDFs,
    Graphviz files, README.md, manifest.xml and git files aside)."""
    if ctx.compare.path == ctx.compare.folder:
        return skipped(test.name, "the compare model is a single file, not a folder")
    old, new = _files(ctx.compare.folder), _files(ctx.built.folder)
    lost = sorted(old - new)
    added = sorted(new - old)
    details = (*(f"missing: {f}" for f in lost), *(f"added: {f}" for f in added))
    if lost:
        return failed(test.name, f"{_files_of(len(lost))} missing, e.g. '{lost[0]}'",
                      figure=float(len(lost)), unit="files", details=details)
    return passed(test.name, f"all {_files_of(len(old))} there", figure=0.0, unit="files", details=details)


def _files_of(n: int) -> str:
    return f"{n} file of the compare model is" if n == 1 else f"{n} files of the compare model are"
