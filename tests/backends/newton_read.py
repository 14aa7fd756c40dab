"""Newton's reading of USD assets, as JSON (run as `python -m tests.backends.newton_read PATH…`).

Run in a process of its own: Newton registers its USD schemas (newton-usd-schemas, where
NewtonMimicAPI is) when it is imported, and usd-core builds its schema registry once, at the
first stage a process opens; a test process has opened stages before.
"""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any


def read(path: str) -> dict[str, Any]:
    import newton

    builder = newton.ModelBuilder()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        builder.add_usd(path)
        model = builder.finalize(device="cpu")
    joints = list(builder.joint_label)
    return {
        "bodies": {label: {"mass": float(m), "com": [float(c) for c in com],
                           "inertia": [[float(x) for x in row] for row in inertia]}
                   for label, m, com, inertia in zip(builder.body_label, model.body_mass.numpy(),
                                                     model.body_com.numpy(), model.body_inertia.numpy(),
                                                     strict=True)},
        "joints": {label: {"type": int(builder.joint_type[i]), "parent": builder.joint_parent[i],
                           "child": builder.joint_child[i],
                           "mimic": joints[builder.joint_mimic_joint[i]] if builder.joint_mimic_joint[i] >= 0
                           else None, "coeffs": [float(c) for c in builder.joint_mimic_coeffs[i]]}
                   for i, label in enumerate(joints)},
        "dof_limits": {joints[i]: [float(lo), float(hi)] for i, lo, hi in _dof_limits(builder, model)},
        "velocity_limits": {joints[i]: float(v) for i, v in _per_dof(builder, model.joint_velocity_limit)},
        "frictions": {joints[i]: float(v) for i, v in _per_dof(builder, model.joint_friction)},
    }


def _dof_limits(builder: Any, model: Any) -> list[tuple[int, float, float]]:
    """(joint, lower, upper) of each joint with one degree of freedom."""
    lower, upper = model.joint_limit_lower.numpy(), model.joint_limit_upper.numpy()
    starts = [*builder.joint_qd_start, len(lower)]
    return [(i, lower[starts[i]], upper[starts[i]]) for i in range(len(builder.joint_label))
            if starts[i + 1] - starts[i] == 1]


def _per_dof(builder: Any, values: Any) -> list[tuple[int, float]]:
    """(joint, value) of each joint with one degree of freedom."""
    array = values.numpy()
    starts = [*builder.joint_qd_start, len(array)]
    return [(i, array[starts[i]]) for i in range(len(builder.joint_label)) if starts[i + 1] - starts[i] == 1]


def newton_reads(paths: list[Path]) -> dict[str, dict[str, Any]]:
    """Each asset as Newton reads it, in one process of its own (see the module)."""
    done = subprocess.run([sys.executable, "-m", "tests.backends.newton_read", *map(str, paths)],
                          capture_output=True, text=True, check=False, cwd=Path(__file__).parents[2])
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


if __name__ == "__main__":
    out = {p: read(p) for p in sys.argv[1:]}
    sys.stdout.flush()
    print(json.dumps(out))
