"""Compile one model definition: YAML on disk → finished model files on disk.

`compile_model` reads as a list of named phases; each stops the build when it
reported an error. Outputs are built in a temporary folder beside the output and
renamed into place only when everything succeeded, so a failed build leaves the
previous outputs untouched.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from mpc.backends.packages import PackageResolver
from mpc.compiler import schema, source
from mpc.compiler.diagnostics import Sink
from mpc.compiler.lower import lower
from mpc.compiler.passes import PassContext, run_passes
from mpc.ir.program import Program
from mpc.ir.robot import Robot


@dataclass
class Options:
    """How to compile: where outputs go, how packages are found."""

    out: Path | None = None
    resolver: PackageResolver = field(default_factory=PackageResolver)


@dataclass
class Result:
    """What a compilation produced: the program, the robot and the output folder."""

    program: Program | None = None
    robot: Robot | None = None
    out: Path | None = None


def front_end(path: Path, sink: Sink, options: Options) -> Program | None:
    """Load, validate, lower and run passes; the program or None."""
    doc = source.load(path, sink)                                    # load sources
    if doc is None:
        return None
    ast = schema.validate(doc, sink)                                 # validate schema
    if ast is None:
        return None
    program = lower(ast, path.resolve().parent, sink, options.resolver)  # lower
    if program is None:
        return None
    program = run_passes(program, PassContext(sink))                 # run passes
    return None if sink.has_errors() else program


def apply(program: Program, sink: Sink, options: Options) -> Robot | None:
    """Read the inputs and run the ops; the robot or None."""
    from mpc.backends import urdf

    base = program.inputs[program.base]
    robot = urdf.read(base.path, sink, options.resolver)
    if robot is None:
        return None
    for op in program.ops:
        robot = op.apply(robot)
    return robot


def emit(program: Program, robot: Robot, out: Path, sink: Sink) -> bool:
    """Write every export into a fresh folder next to `out`, then swap it into place."""
    from mpc.backends import BACKENDS

    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".mpc-tmp", dir=out.parent))
    try:
        for export in program.exports:
            BACKENDS[export.type]().emit(robot, export, staging, sink)
        if sink.has_errors():
            return False
        _replace(staging, out)
        return True
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _replace(new: Path, out: Path) -> None:
    """Put `new` where `out` is; the old `out` disappears only after `new` is in place."""
    if not out.exists():
        os.replace(new, out)
        return
    old = out.with_name(f".{out.name}.mpc-old-{os.getpid()}")
    os.replace(out, old)
    try:
        os.replace(new, out)
    except OSError:
        os.replace(old, out)
        raise
    shutil.rmtree(old, ignore_errors=True)


def compile_model(path: Path, sink: Sink, options: Options) -> Result:
    """Compile the definition at `path`; diagnostics go to `sink`."""
    result = Result()
    result.program = front_end(path, sink, options)      # front end: load, validate, lower, passes
    if result.program is None:
        return result
    result.robot = apply(result.program, sink, options)  # read inputs, apply ops
    if result.robot is None:
        return result
    out = options.out or Path("build") / result.program.modelname
    if emit(result.program, result.robot, out, sink):    # emit, rename into place
        result.out = out
    return result
