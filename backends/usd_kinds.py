"""Which joints and loop closures a USD export writes (backends/usd_stage.py) and which it
names in W0500 instead (backends/usd.py): one answer for both, without loading usd-core."""

from __future__ import annotations

from mpc.backends.mjcf import cut_axis
from mpc.ir.extras import CutJoint
from mpc.ir.robot import Joint

ONE_DOF = ("revolute", "continuous", "prismatic")


def mimic_written(joint: Joint, leader: Joint | None) -> bool:
    """NewtonMimicAPI couples two one-degree-of-freedom joints of one kind (both rotational or
    both translational)."""
    return leader is not None and joint.type in ONE_DOF and leader.type in ONE_DOF \
        and (joint.type == "prismatic") == (leader.type == "prismatic")


def closed_cut_axis(cut: CutJoint) -> tuple[float, float, float] | None:
    """A revolute closure's axis in its child link's frame (mjcf.cut_axis), or None."""
    a = cut_axis(cut)
    return None if a is None else (float(a[0]), float(a[1]), float(a[2]))


def written_cut(cut: CutJoint) -> bool:
    """Whether a UsdPhysics joint holds the closure: fixed, ball, or rotational with an axis."""
    rotational = cut.type in ("revolute", "continuous")
    return cut.type in ("fixed", "ball") or (rotational and cut_axis(cut) is not None)
