"""usd-core's modules, as the usd export uses them, typed `Any`: usd-core's bindings are C++
and ship no type information, so a type checker sees none of their attributes. The names
below stand for its types in annotations."""

from __future__ import annotations

from typing import Any, TypeAlias

from pxr import Gf as _Gf
from pxr import Sdf as _Sdf
from pxr import Tf as _Tf
from pxr import Usd as _Usd
from pxr import UsdGeom as _UsdGeom
from pxr import UsdPhysics as _UsdPhysics
from pxr import UsdShade as _UsdShade
from pxr import Vt as _Vt

Gf: Any = _Gf
Sdf: Any = _Sdf
Tf: Any = _Tf
Usd: Any = _Usd
UsdGeom: Any = _UsdGeom
UsdPhysics: Any = _UsdPhysics
UsdShade: Any = _UsdShade
Vt: Any = _Vt

Layer: TypeAlias = Any  # Sdf.Layer
PrimPath: TypeAlias = Any  # Sdf.Path
Prim: TypeAlias = Any  # Usd.Prim
Stage: TypeAlias = Any  # Usd.Stage
Quat: TypeAlias = Any  # Gf.Quatd, Gf.Quatf
Xformable: TypeAlias = Any  # UsdGeom.Xformable
PhysicsJoint: TypeAlias = Any  # UsdPhysics.Joint
