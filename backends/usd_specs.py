"""Authoring straight into a layer's specs (Sdf), as the usd export does, rather than through a
stage: a stage composes again after every change, which made the same authoring 2.5 times
slower (TALOS's geometry: 56 ms against 22). What the stage's schema classes would write is
written here by hand: each attribute's name, type and variability as the schema declares it,
API schemas prepended in the order they are applied, and targets and connections explicit."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeAlias

from mpc.backends.usd_pxr import Layer, PrimPath, Sdf, Vt

PrimSpec: TypeAlias = Any  # Sdf.PrimSpec
T: Any = Sdf.ValueTypeNames


def prim(layer: Layer, path: PrimPath, type_name: str | None = None) -> PrimSpec:
    """The spec of `path` in `layer`, created (with `over` ancestors) when absent: a definition
    of `type_name` when given ("" for a typeless `def`), else as it is (an `over` when new)."""
    spec = layer.GetPrimAtPath(path) or Sdf.CreatePrimInLayer(layer, path)
    if type_name is not None:
        spec.specifier = Sdf.SpecifierDef
        spec.typeName = type_name
    return spec


def attribute(spec: PrimSpec, name: str, type_name: Any, value: Any, *, uniform: bool = False,
              custom: bool = False) -> None:
    """An attribute with its default value (a schema's own attribute: `custom` False)."""
    variability = Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying
    Sdf.AttributeSpec(spec, name, type_name, variability, custom).default = value


def relationship(spec: PrimSpec, name: str, targets: Sequence[PrimPath]) -> None:
    Sdf.RelationshipSpec(spec, name, False).targetPathList.explicitItems = list(targets)


def connect(spec: PrimSpec, name: str, type_name: Any, source: PrimPath) -> None:
    """An attribute connected to `source` (a shading output), without a value."""
    Sdf.AttributeSpec(spec, name, type_name).connectionPathList.explicitItems = [source]


def apply(spec: PrimSpec, *schemas: str) -> None:
    """Apply API schemas (`prepend apiSchemas`, after those applied before)."""
    before = spec.GetInfo("apiSchemas") if spec.HasInfo("apiSchemas") else None
    listed = list(before.prependedItems) if before is not None else []
    op = Sdf.TokenListOp()
    op.prependedItems = [*listed, *(s for s in schemas if s not in listed)]
    spec.SetInfo("apiSchemas", op)


def place(spec: PrimSpec, translate: Any = None, orient: Any = None, scale: Any = None) -> None:
    """The xform ops given (Gf.Vec3d, Gf.Quatd, Gf.Vec3d: doubles), in this order."""
    order = []
    for op, value, type_name in (("translate", translate, T.Double3), ("orient", orient, T.Quatd),
                                 ("scale", scale, T.Double3)):
        if value is not None:
            attribute(spec, f"xformOp:{op}", type_name, value)
            order.append(f"xformOp:{op}")
    if order:
        attribute(spec, "xformOpOrder", T.TokenArray, Vt.TokenArray(order), uniform=True)
