"""Backends: one module per file format, imported only when that format is used."""

from __future__ import annotations

import importlib
from types import ModuleType

_MODULES = {
    "urdf": "mpc.backends.urdf",
    "mjcf": "mpc.backends.mjcf",
    "sdf": "mpc.backends.sdf",
    "smurf": "mpc.backends.smurf",
    "pdf": "mpc.backends.pdf",
    "render": "mpc.backends.render",
    "joint_limits": "mpc.backends.joint_limits",
    "kccd": "mpc.backends.kccd",
    "ros_package": "mpc.backends.ros_package",
}


class _Lazy:
    def __init__(self, module: str) -> None:
        self.module = module

    def __call__(self) -> ModuleType:
        return importlib.import_module(self.module)


BACKENDS: dict[str, _Lazy] = {name: _Lazy(module) for name, module in _MODULES.items()}
