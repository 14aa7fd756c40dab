"""usd-core's modules, as the usd export uses them, typed `Any`: usd-core's bindings are C++
and ship no type information, so a type checker sees none of their attributes. The names
below stand for its types in annotations.

Only Sdf and the value types: the export authors specs into layers (backends/usd_specs.py),
so it loads none of Usd's stage or schema modules (0.07 s of imports: `mpc compile`'s start)."""

from __future__ import annotations

from typing import Any, TypeAlias

from pxr import Gf as _Gf
from pxr import Sdf as _Sdf
from pxr import Tf as _Tf
from pxr import Vt as _Vt

Gf: Any = _Gf
Sdf: Any = _Sdf
Tf: Any = _Tf
Vt: Any = _Vt

Layer: TypeAlias = Any  # Sdf.Layer
PrimPath: TypeAlias = Any  # Sdf.Path
Quat: TypeAlias = Any  # Gf.Quatd, Gf.Quatf
