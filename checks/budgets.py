"""Budgets: tests that fail when the compiled model exceeds a limit the definition gives.

max_mesh_faces: the faces of the largest mesh file; max_mesh_bytes: the total size of the
mesh files (each file once, however many elements use it); max_collisions_per_link: the
collision shapes of the link with the most (a convex decomposition's hulls count one each).
The meshes are those the compiled model references (visuals and collisions).
"""

from __future__ import annotations

from pathlib import Path

from mpc.checks.protocol import Result, counted, failed, first_of, verdict
from mpc.checks.registry import Context, register
from mpc.ir.geometry import Mesh
from mpc.ir.program import ModelTest
from mpc.ir.robot import Robot


def _mesh_files(robot: Robot) -> tuple[dict[Path, Mesh], list[str]]:
    """The mesh files the robot uses (each once), and a problem for each it names but lacks."""
    from mpc.backends.meshes import mesh_uses

    files: dict[Path, Mesh] = {}
    problems: list[str] = []
    for use in mesh_uses(robot):
        path = use.mesh.source.path
        if path is None or not path.is_file():
            why = use.mesh.source.unresolved or "the file does not exist"
            problems.append(f"the {use.element} mesh '{use.mesh.source.uri}' of link '{use.link}' "
                            f"cannot be measured: {why}")
        else:
            files.setdefault(path, use.mesh)
    return files, problems


def faces(path: Path, mesh: Mesh) -> int:
    """The faces (triangles) of a mesh file: a binary STL's from its header, others read."""
    from mpc.backends.empty_meshes import binary_stl_triangles

    if path.suffix.lower() == ".stl" and (count := binary_stl_triangles(path)) is not None:
        return count
    from mpc.ir.mesh_props import as_trimesh

    return len(as_trimesh(Mesh(source=mesh.source), scaled=False).faces)


def _over(name: str, figures: dict[str, float], limit: float, unit: str, noun: str,
          problems: list[str]) -> Result:
    """The verdict of a budget: the largest figure against the limit; details worst first."""
    if problems:
        return failed(name, first_of(problems), details=tuple(problems))
    rows = sorted(figures.items(), key=lambda kv: (-kv[1], kv[0]))
    over = [f"{key}: {counted(value, noun)} > {limit:g}" for key, value in rows if value > limit]
    worst = rows[0][1] if rows else 0.0
    reason = first_of(over) if over else (f"the largest, {rows[0][0]}: {counted(worst, noun)} ≤ {limit:g}"
                                          if rows else f"nothing to count: 0 {unit} ≤ {limit:g}")
    return verdict(name, not over, reason, figure=float(worst), unit=unit, details=tuple(over))


@register("max_mesh_faces")
def max_mesh_faces(ctx: Context, test: ModelTest) -> Result:
    """The largest mesh file's faces ≤ the limit."""
    assert test.value is not None
    files, problems = _mesh_files(ctx.built.robot)
    counts: dict[str, float] = {}
    for path, mesh in files.items():
        try:
            counts[f"'{_shown(path, ctx.built.folder)}'"] = float(faces(path, mesh))
        except Exception as e:  # a mesh trimesh cannot read: the budget cannot be judged
            problems.append(f"mesh '{_shown(path, ctx.built.folder)}' cannot be read: {e}")
    return _over(test.name, counts, test.value, "faces", "face", problems)


@register("max_mesh_bytes")
def max_mesh_bytes(ctx: Context, test: ModelTest) -> Result:
    """The total size of the mesh files ≤ the limit; the details name the largest files."""
    assert test.value is not None
    files, problems = _mesh_files(ctx.built.robot)
    sizes = {f"'{_shown(p, ctx.built.folder)}'": float(p.stat().st_size) for p in files}
    total = sum(sizes.values())
    if problems:
        return failed(test.name, first_of(problems), details=tuple(problems))
    largest = sorted(sizes.items(), key=lambda kv: (-kv[1], kv[0]))[:10]
    details = tuple(f"{key}: {size:g} bytes" for key, size in largest)
    ok = total <= test.value
    return verdict(test.name, ok, f"{counted(len(files), 'mesh file')}, {total:g} bytes {'≤' if ok else '>'} "
                   f"{test.value:g}", figure=total, unit="bytes", details=() if ok else details)


@register("max_collisions_per_link")
def max_collisions_per_link(ctx: Context, test: ModelTest) -> Result:
    """The collision shapes of each link ≤ the limit."""
    assert test.value is not None
    counts = {f"link '{n}'": float(len(link.collisions)) for n, link in ctx.built.robot.links.items()}
    return _over(test.name, counts, test.value, "collisions", "collision", [])


def _shown(path: Path, folder: Path) -> str:
    """A mesh file relative to the model's folder when inside it (the protocol goes into a
    merge request: no runner's folders), else its name."""
    try:
        return path.resolve().relative_to(folder.resolve()).as_posix()
    except ValueError:
        return path.name
