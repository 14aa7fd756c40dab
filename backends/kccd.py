"""ir.Robot → the collision model KCCD reads: one convex hull per body, the URDF urdf2kccd
reads, and the KCCD settings; KCCD's own files come from its tools (backends/kccd_tools.py).

Layout (Phobos's): the hulls as `meshes/iv/collision_<link>.stl`, `<dirname>/<robot>.urdf`
(each body's hull as its visual and collision: urdf2kccd reads visuals), and
`<dirname>/<robot>_kccd.yml`, the settings Phobos writes into urdf2kccd's `<robot>.cfg`
(safety distance, braking model, …) with what mpc computes for it: each body's mesh and
number of cover points, the joints simplified to order 0, the body pairs not to check.

Bodies: `remove_joints` first merges those joints' child links into their parents
(ir/merge.py). Then a body is a link whose parent joint is movable and not in
`merge_additionally`, with every link hanging from it by fixed or merge_additionally
joints. Its hull covers the bodies' visuals (Phobos's choice: urdf2kccd models the visible
shape); a body without visuals uses its collisions. Primitives are meshed (trimesh).
Not done: kccdcoveriv's fitted volumes and urdf2kccd's `.cfg` without the tools.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from mpc.backends.urdf_writer import to_string
from mpc.backends.xml import write_path
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.files import confined, file_name
from mpc.core.record import record
from mpc.ir.geometry import Mesh, MeshSource
from mpc.ir.kinematics import links_in_root, pose_matrix
from mpc.ir.program import KccdExport
from mpc.ir.robot import Collision, Robot, Visual
from mpc.ir.tree import child_joints, depth_first, movable_above, parent_joint

MESH_DIR = "meshes/iv"
# Cover points for a shape KCCD fits exactly (edit_collisions `shape`), as Phobos counts them.
SHAPE_POINTS = {"cylinder": 2, "box": 8, "sphere": 1}


@record
class Body:
    """A KCCD body: its link, the links merged into it (depth-first) and each one's pose X_BL."""

    link: str
    links: tuple[str, ...]
    poses: tuple[np.ndarray, ...]

    @property
    def mesh(self) -> str:
        """The hull's path in the output folder."""
        return f"{MESH_DIR}/collision_{file_name(self.link, 'link')}.stl"


def emit(robot: Robot, export: KccdExport, out: Path, sink: Sink) -> None:
    """Write the hulls, the KCCD URDF and the settings; run urdf2kccd and kccdcoveriv when
    they are installed, else say what they would have written (W0520)."""
    from mpc.backends.kccd_tools import run_tools

    model = prepared(robot, export, sink)
    if model is None:
        return
    bodies = bodies_of(model, export)
    if not _check_links(model, bodies, export, sink):
        return
    hulls: dict[str, Any] = {}
    for body in bodies:
        hull = hull_of(model, body, export, sink)
        if hull is None:
            continue
        hulls[body.link] = hull
        data = hull.export(file_type="stl")
        path = confined(out, body.mesh)
        if path.exists() and path.read_bytes() != data:
            sink.error(export.span, "E0525", f"two kccd exports write different hulls to {body.mesh}")
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    if sink.has_errors():
        return
    kept = [b for b in bodies if b.link in hulls]
    folder = confined(out, export.dirname)
    robot_name = file_name(model.name, "robot")
    urdf = confined(folder, f"{robot_name}.urdf")
    up = "../" * len(Path(export.dirname).parts)  # from the KCCD folder to the output's
    write_path(urdf, to_string(kccd_urdf(model, kept), lambda m: up + m.source.uri))
    settings = settings_of(model, bodies, hulls, export)
    write_path(confined(folder, f"{robot_name}_kccd.yml"),
               json.dumps(settings, indent=2, sort_keys=True) + "\n")
    run_tools(folder, robot_name, settings, export, [confined(out, b.mesh) for b in kept], sink)


def prepared(robot: Robot, export: KccdExport, sink: Sink) -> Robot | None:
    """The robot with remove_joints merged; None (E0522) when an export names what is not there."""
    from mpc.ir.merge import merge_joints

    ok = _names(export, "remove_joints", export.remove_joints, robot, sink)
    model = merge_joints(robot, export.remove_joints, sink, export.span) if ok else None
    if model is None:
        return None
    return model if _names(export, "merge_additionally", export.merge_additionally, model, sink) else None


def _names(export: KccdExport, key: str, names: tuple[str, ...], robot: Robot, sink: Sink) -> bool:
    ok = True
    above = {j.child: j.name for j in robot.joints.values()}
    for name in names:
        if name not in robot.joints:
            hint = f"give the joint above it, '{above[name]}'" if name in above else None
            sink.error(export.span, "E0522", f"{_kccd(export)} {key} names '{name}', which is not a "
                       f"joint of the model{'' if hint else did_you_mean(name, set(robot.joints))}",
                       hint=hint)
            ok = False
    return ok


def _kccd(export: KccdExport) -> str:
    """How messages name the export: `kccd`, or `kccd of submodel 'x'`."""
    return f"kccd of submodel '{export.submodel}'" if export.submodel else "kccd"


def bodies_of(robot: Robot, export: KccdExport) -> list[Body]:
    """The bodies in depth-first order, each with the links merged into it."""
    children = child_joints(robot)
    merged = set(export.merge_additionally)
    out = []
    for joint, link in depth_first(robot):
        if joint is not None and (joint.type == "fixed" or joint.name in merged):
            continue
        links, poses = [], []
        stack = [(link, np.eye(4))]
        while stack:
            name, X_BL = stack.pop()
            links.append(name)
            poses.append(X_BL)
            for j in reversed(children.get(name, [])):
                if j.type == "fixed" or j.name in merged:
                    stack.append((j.child, X_BL @ pose_matrix(j.origin)))
        out.append(Body(link, tuple(links), tuple(poses)))
    return out


def _check_links(robot: Robot, bodies: list[Body], export: KccdExport, sink: Sink) -> bool:
    """The links the settings name are links of the KCCD model (bodies where they must be)."""
    body_links = {b.link for b in bodies}
    ok = True

    def check(name: str, key: str, needs_body: bool) -> None:
        nonlocal ok
        known = body_links if needs_body else set(robot.links)
        if name not in known:
            what = "a body (a link whose parent joint is movable)" if needs_body else "a link"
            sink.error(export.span, "E0522", f"{_kccd(export)} {key} names '{name}', which is not "
                       f"{what} of the KCCD model{did_you_mean(name, known)}")
            ok = False

    for link in export.simplify_swept_from:
        check(link, "simplify_swept_from", False)
    for link in (*export.n_points, *export.shapes):
        check(link, "edit_collisions", True)
    for link, others in export.no_collision_between.items():
        for name in (link, *others):
            check(name, "no_collision_between", False)
    return ok


def hull_of(robot: Robot, body: Body, export: KccdExport, sink: Sink) -> Any:
    """The body's hull in its link's frame (trimesh), or None for a body without shapes."""
    import trimesh

    from mpc.ir.mesh_props import MeshError, as_trimesh

    elements: list[Any] = [v for link in body.links for v in robot.links[link].visuals]
    use_visuals = bool(elements)
    pieces = []
    for link, X_BL in zip(body.links, body.poses, strict=True):
        lk = robot.links[link]
        for element in (lk.visuals if use_visuals else lk.collisions):
            try:
                piece = as_trimesh(element.geometry)
            except MeshError as e:
                sink.error(export.span, "E0603", f"kccd hull of link '{body.link}': {e}")
                return None
            piece.apply_transform(X_BL @ pose_matrix(element.origin))
            pieces.append(piece if export.join_before_convexhull else piece.convex_hull)
    if not pieces:
        return None
    mesh = trimesh.util.concatenate(pieces)
    if export.join_before_convexhull:
        mesh = mesh.convex_hull
    faces = len(mesh.faces)
    target = export.reduce_faces
    if export.reduce_ratio:
        target = math.ceil((1 - export.reduce_ratio) * faces)
    if 4 <= target < faces:
        mesh = _fewer_faces(mesh, target) if export.join_before_convexhull \
            else mesh.simplify_quadric_decimation(face_count=target)
    return mesh


def _fewer_faces(hull: Any, faces: int) -> Any:
    """A convex hull with at most `faces` faces: the hull of faces/2 + 2 of its vertices
    (a closed convex mesh has at most 2·V − 4 faces), taken farthest-first from the vertex
    farthest from the centre. Quadric decimation, Phobos's way, neither keeps a hull convex
    nor gets a hull's slivers below a few hundred faces."""
    points = np.asarray(hull.vertices)
    count = min(faces // 2 + 2, len(points))
    chosen = [int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))]
    distance = np.linalg.norm(points - points[chosen[0]], axis=1)
    while len(chosen) < count:
        chosen.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.linalg.norm(points - points[chosen[-1]], axis=1))
    import trimesh

    return trimesh.convex.convex_hull(points[chosen])


def kccd_urdf(robot: Robot, bodies: list[Body]) -> Robot:
    """The model urdf2kccd reads: links and joints, each body's hull as its only visual and
    collision; no materials, fragments, comments or SMURF data."""
    links = {}
    hull = {b.link: b.mesh for b in bodies}
    for name, link in robot.links.items():
        shapes: tuple[Any, ...] = ()
        if name in hull:
            mesh = Mesh(source=MeshSource(uri=hull[name], path=None))
            shapes = (Visual(name=f"collision_{name}", geometry=mesh),)
            links[name] = replace(link, visuals=shapes, collisions=(
                Collision(name=f"collision_{name}", geometry=mesh),), **_BARE)
        else:
            links[name] = replace(link, visuals=(), collisions=(), **_BARE)
    return Robot(name=robot.name, root=robot.root, links=links,
                 joints={n: replace(j, **_BARE) for n, j in robot.joints.items()})


_BARE: dict[str, Any] = {"extras": (), "comments": (), "inner_comments": ()}


def settings_of(robot: Robot, bodies: list[Body], hulls: dict[str, Any],
                export: KccdExport) -> dict[str, Any]:
    """The KCCD settings file's content (see the module docstring); bodies without a hull
    (no shapes) are left out."""
    up = "../" * len(Path(export.dirname).parts)
    above = movable_above(robot)
    out: dict[str, Any] = {
        "robot": robot.name, "urdf": f"{robot.name}.urdf",
        "safety_distance": _number(export.safety_distance), "report_up_to": _number(export.report_up_to),
        "computation_budget": _number(export.computation_budget),
        "max_approximation_order": export.max_approximation_order,
        "bodies": [{"link": b.link, "links": list(b.links), "mesh": up + b.mesh,
                    "n_points": n_points(b.link, export, above)} for b in bodies if b.link in hulls],
        "dont_check": [list(pair) for pair in dont_check(robot, bodies, hulls, export)],
    }
    if export.braking_model:
        keys = ("linearFactor", "invDeceleration", "uncertainty", "latency")
        out["braking_model"] = {k: _number(v) for k, v in zip(keys, export.braking_model, strict=True)}
    if export.simplify_swept_from:
        out["order_0_joints"] = {link: swept_joints(robot, link) for link in export.simplify_swept_from}
    return out


def _number(x: float) -> int | float:
    return int(x) if float(x).is_integer() else x


def n_points(link: str, export: KccdExport, movable: Mapping[str, int]) -> int:
    """How many points kccdcoveriv covers the body with: fewer the more movable joints lie
    between it and the root (Phobos's rule, 25 at the root towards 3), unless edit_collisions
    gives a number or a shape. movable: `movable_above` of the robot."""
    if link in export.n_points:
        return export.n_points[link]
    if export.shapes.get(link, "convex") != "convex":
        return SHAPE_POINTS[export.shapes[link]]
    return int((25 - 3) * 0.4 ** (movable[link] / 3) + 3)


def swept_joints(robot: Robot, link: str) -> list[str]:
    """The movable joints below `link` (simplify_swept_from: KCCD computes their swept volume
    with order 0)."""
    from mpc.ir.names import Names

    below = Names.of(robot).subtree(link)
    return [j.name for j, child in depth_first(robot) if j is not None and j.type != "fixed"
            and child in below and child != link]


def _touching_boxes(hulls: dict[str, Any], X_R: Mapping[str, np.ndarray]) -> list[tuple[str, str]]:
    """Pairs of hulls whose bounding boxes (axis-aligned in the root frame, at q = 0) touch;
    sweeps along x, so only boxes that overlap in x are compared."""
    boxes = []
    for link, hull in hulls.items():
        points = (X_R[link] @ np.c_[hull.vertices, np.ones(len(hull.vertices))].T).T[:, :3]
        boxes.append((points.min(axis=0), points.max(axis=0), link))
    boxes.sort(key=lambda box: box[0][0])
    out = []
    for i, (low_a, high_a, a) in enumerate(boxes):
        for low_b, high_b, b in boxes[i + 1:]:
            if low_b[0] > high_a[0]:
                break
            if np.all(low_a <= high_b) and np.all(low_b <= high_a):
                out.append((a, b))
    return out


def dont_check(robot: Robot, bodies: list[Body], hulls: dict[str, Any],
               export: KccdExport) -> list[tuple[str, str]]:
    """Body pairs KCCD need not check (Phobos's collision matrix): a body and its parent body;
    a body and the ancestors of its parent body reached by rotations only (their frames share
    an origin); bodies whose hulls' bounding boxes touch at q = 0; and no_collision_between."""
    body_of = {link: b.link for b in bodies for link in b.links}
    parents = parent_joint(robot)
    parent_body = {b.link: body_of[parents[b.link].parent] for b in bodies if b.link in parents}
    X_R = links_in_root(robot)
    pairs: set[tuple[str, str]] = set()

    def add(a: str, b: str) -> None:
        if a != b and a in hulls and b in hulls:
            pairs.add((min(a, b), max(a, b)))

    for b in bodies:
        parent = parent_body.get(b.link)
        if parent is None:
            continue
        add(b.link, parent)
        while parent in parent_body:
            X = np.linalg.inv(X_R[parent_body[parent]]) @ X_R[parent]
            if not np.allclose(X[:3, 3], 0.0, atol=1e-2):
                break
            parent = parent_body[parent]
            add(b.link, parent)
    for a, b in _touching_boxes(hulls, X_R):
        add(a, b)
    for link, others in export.no_collision_between.items():
        for other in others:
            add(body_of[link], body_of[other])
    return sorted(pairs)
