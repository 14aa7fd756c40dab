"""Facts of the language's `float_fmt_dict`: the keys each export type accepts (the attributes
or elements whose values are numbers its writer writes), `default`, and what a format is.
Each format's descriptor names its keys (backends/formats.py `float_keys`); lowering checks a
definition against them; backends/float_formats.py applies the formats.
"""

from __future__ import annotations

import re

# The attributes (URDF) and elements (SDF) whose values are numbers the writers write.
URDF_KEYS = frozenset({
    "xyz", "rpy", "size", "radius", "length", "scale", "rgba", "value", "ixx", "ixy", "ixz", "iyy",
    "iyz", "izz", "lower", "upper", "effort", "velocity", "damping", "friction", "multiplier",
    "offset", "rising", "falling", "reference_position", "soft_lower_limit", "soft_upper_limit",
    "k_position", "k_velocity"})
SDF_KEYS = frozenset({
    "pose", "mass", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "size", "radius", "length", "scale",
    "ambient", "diffuse", "specular", "emissive", "transparency", "xyz", "lower", "upper", "effort",
    "velocity", "damping", "friction"})
MJCF_KEYS = frozenset({
    "pos", "quat", "mass", "diaginertia", "size", "axis", "range", "rgba", "scale", "polycoef",
    "damping", "frictionloss", "actuatorfrcrange", "ctrlrange", "forcerange", "kp", "kv", "dampratio",
    "qpos", "ctrl"})
DEFAULT = "default"
_FORMAT = re.compile(r"%[-+ 0#]*[0-9]{0,2}(\.[0-9]{1,2})?[eEfFgG]")


def bad_format(fmt: str) -> bool:
    """Whether `fmt` is not a printf format of one floating-point number (`%.6f`, `%g`, …)."""
    return not _FORMAT.fullmatch(fmt)
