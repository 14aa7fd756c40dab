"""Re-root a robot at one of its links: `frames: <link>: make_root` and attaching at a
`joint: child:` other than the child model's root (both are Phobos's `exchange_root`).

For a joint j on the way from the old root to the new one, from P to C with origin O, the
reversed joint goes from C to P with origin A_C⁻¹ and axis −a (so q keeps its meaning and
its limits); P's frame moves to the old joint frame (A_P = O: a URDF joint's frame is its
child link's frame), and everything given in P — visuals, collisions, inertial, the joints
to its other children — is re-expressed: X_F V = O⁻¹ · X_P V, so nothing moves in space.
The new root's frame and the frames of the links off the way do not change.
"""

from __future__ import annotations

from dataclasses import replace

from mpc.ir import refs as declared
from mpc.ir.names import Names
from mpc.ir.robot import Pose, Robot
from mpc.ir.tree import joints_up


class RerootError(ValueError):
    """A robot that cannot be re-rooted as asked (the message says why)."""


def reroot(robot: Robot, root: str) -> Robot:
    """`robot` with `root` as its root link. RerootError for a sensor or loop-closure joint
    placed on a link whose frame moves (mpc does not re-express those)."""
    from mpc.ir.kinematics import compose_poses, inverse_pose  # numpy: not on `mpc check`'s path

    path = joints_up(robot, root)
    if not path:
        return robot
    joints, links = dict(robot.joints), dict(robot.links)
    moved: dict[str, Pose] = {root: Pose()}  # A_P: each path link's new frame in its old one
    for joint in path:  # from `root` up to the old root
        moved[joint.parent] = joint.origin or Pose()
    # What is placed in a link's frame: the links a loop joint or a sensor names (ir/refs.py).
    placed = [(kind, item.name, {name for ref, name, _ in declared.refs(item)
                                 if ref.kinds == ("link",) and not ref.defines})
              for kind, items in (("loop-closure joint", robot.cut_joints), ("sensor", robot.sensors))
              for item in items.values()]
    for kind, name, on in placed:
        if on & (set(moved) - {root}):
            raise RerootError(f"the {kind} '{name}' is placed in the frame of "
                              f"{', '.join(sorted(on & (set(moved) - {root})))}, which re-rooting "
                              "moves; mpc does not re-express it")
    for joint in path:
        axis = joint.axis
        if joint.type not in ("fixed", "floating"):
            axis = tuple(-x + 0.0 for x in (joint.axis or (1.0, 0.0, 0.0)))
        joints[joint.name] = replace(joint, parent=joint.child, child=joint.parent, axis=axis,
                                     origin=inverse_pose(moved[joint.child]))
    on_path = {j.name for j in path}
    for name, A in moved.items():
        if name == root:
            continue
        A_inv = inverse_pose(A)
        lk = links[name]
        inertial = lk.inertial
        links[name] = replace(
            lk, inertial=inertial and replace(inertial, origin=compose_poses(A_inv, inertial.origin)),
            visuals=tuple(replace(v, origin=compose_poses(A_inv, v.origin)) for v in lk.visuals),
            collisions=tuple(replace(c, origin=compose_poses(A_inv, c.origin)) for c in lk.collisions))
        for jname, j in robot.joints.items():
            if j.parent == name and jname not in on_path:
                joints[jname] = replace(j, origin=compose_poses(A_inv, j.origin))
    return replace(robot, root=root, joints=joints, links=links)


def reroot_names(names: Names, root: str) -> Names:
    """The names after `reroot`: the joints on the way to `root` reversed."""
    above = {child: (joint, parent) for joint, (parent, child) in names.joints.items()}
    joints = dict(names.joints)
    link = root
    while link in above:
        joint, parent = above[link]
        joints[joint] = (link, parent)
        link = parent
    return replace(names, joints=joints, root=root)
