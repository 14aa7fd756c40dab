"""resolve_inputs: every input model's file exists and is a format mpc reads.

    input_models: {torso: {basefile: torso.urdf}}   # no such file
    → error[E0601]: basefile 'torso.urdf' of input model 'torso' does not exist
"""

from __future__ import annotations

from mpc.backends.formats import FORMATS
from mpc.compiler.passes.context import PassContext
from mpc.core.files import why_absent
from mpc.ir.program import Program

# The suffixes of the formats' readers (backends/formats.py), and xacro (compiler/inputs.py).
READABLE = (*(s for f in FORMATS.values() if f.read is not None for s in f.suffixes), ".xacro")


def resolve_inputs(program: Program, ctx: PassContext) -> Program:
    for inp in program.inputs.values():
        if inp.path is None:
            continue
        what = "basefile" if inp.kind == "basefile" else "derived_base definition"
        try:
            exists = inp.path.is_file()
        except OSError as e:  # a name too long, a loop of links
            ctx.sink.error(inp.span, "E0601", f"{what} '{inp.path}' of input model '{inp.name}' "
                           f"cannot be read: {e.strerror}")
            continue
        if not exists:
            ctx.sink.error(inp.span, "E0601", f"{what} '{inp.path}' of input model "
                           f"'{inp.name}' {why_absent(inp.path)}")
        elif inp.kind == "basefile" and inp.path.suffix.lower() not in READABLE:
            ctx.sink.error(inp.span, "E0202", f"reading '{inp.path.suffix}' input models is not "
                           "supported yet; mpc reads URDF (.urdf), SDF (.sdf), SMURF (.smurf), MJCF (.xml, "
                           ".mjcf) and xacro (.xacro)")
    return program
