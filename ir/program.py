"""ir.Program: one model definition, lowered — inputs, ordered ops, exports.

The compiler's output and the input of the apply and emit phases. `mpc compile
--emit ir` prints it; the apply phase reads the inputs and runs the ops in order.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from mpc.ir.ops import Op
from mpc.ir.span import Span


@dataclass(frozen=True, slots=True, kw_only=True)
class Input:
    """An input model.

    name: its key under `input_models`.
    kind: where it comes from (only `basefile`, a file on disk, for now).
    path: the file, resolved against the definition's folder.
    span: the YAML value that names the file.
    """

    name: str
    kind: Literal["basefile"]
    path: Path
    span: Span


@dataclass(frozen=True, slots=True, kw_only=True)
class UrdfExport:
    """A `type: urdf` entry of export_config.

    mesh_format: the format of the meshes it references (`input_type` keeps each
    mesh's own format).
    span: the export_config entry.
    """

    mesh_format: str
    span: Span
    type: Literal["urdf"] = "urdf"


Export = UrdfExport


@dataclass(frozen=True, slots=True, kw_only=True)
class Program:
    """A lowered model definition.

    robotname, modelname: the robot's name in the files; the output's name.
    inputs: input models by name. base: the input the assembly starts from.
    ops: rewrites applied to the base, in order. exports: what to write.
    span: the definition's `model:` section.
    """

    robotname: str
    modelname: str
    inputs: Mapping[str, Input]
    base: str
    ops: tuple[Op, ...]
    exports: tuple[Export, ...]
    span: Span
