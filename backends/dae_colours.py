"""A robot → the same robot with its DAE visuals coloured as their files colour them, for
pictures (backends/scene.py). MuJoCo reads no DAE and gives a geom one colour, so a DAE
visual whose file has several material colours becomes one visual per colour, each a
`MaterialPart` of the file (its meshes computed through the mesh cache as every mesh op
is); a file of one colour gives its visual that colour.

A visual's own colour (its URDF material's rgba) wins, as in SDFormat and Gazebo. A visual
whose ops change more than the triangles' places (a hull, a convex part, a join) keeps one
colour: its triangles are no longer the file's. A file that cannot be read is left as it
is, for the mesh export to report.
"""

from __future__ import annotations

from dataclasses import replace

from mpc.ir.geometry import MaterialPart, Mesh, ReduceMesh, ReflectMesh, ScaleMesh
from mpc.ir.robot import Link, Material, Robot, Visual

KEEP_TRIANGLES = (ReflectMesh, ScaleMesh, ReduceMesh)  # ops that a part of the file goes through alike


def coloured(robot: Robot) -> Robot:
    """`robot` with each DAE visual split or coloured by its file's materials (see the module)."""
    links: dict[str, Link] = {}
    for name, link in robot.links.items():
        visuals = [part for visual in link.visuals for part in _parts(robot, visual)]
        links[name] = link if visuals == list(link.visuals) else replace(link, visuals=tuple(visuals))
    return replace(robot, links=links)


def _own_colour(robot: Robot, visual: Visual) -> bool:
    m = visual.inline_material or robot.materials.get(visual.material or "")
    return m is not None and m.rgba is not None


def _parts(robot: Robot, visual: Visual) -> list[Visual]:
    mesh = visual.geometry
    if not isinstance(mesh, Mesh) or mesh.source.format != "dae" or _own_colour(robot, visual) \
            or not all(isinstance(op, KEEP_TRIANGLES) for op in mesh.ops):
        return [visual]
    path = mesh.source.path
    if path is None or not path.is_file():
        return [visual]
    from mpc.core.collada import material_colours

    try:
        colours = material_colours(path)
    except Exception:  # pycollada and lxml raise many kinds; the mesh export reports it
        return [visual]
    if all(c is None for c in colours):
        return [visual]
    stem = visual.name or path.name.split(".", 1)[0]
    if len(colours) == 1:
        return [replace(visual, inline_material=_material(stem, 0, colours[0]))]
    return [replace(visual, name=f"{visual.name}_material{i}" if visual.name else None,
                    geometry=replace(mesh, ops=(MaterialPart(i), *mesh.ops)),
                    inline_material=_material(stem, i, colour) if colour is not None else None)
            for i, colour in enumerate(colours)]


def _material(stem: str, index: int, rgba: tuple[float, float, float, float] | None) -> Material:
    """The material of part `index`: named after the visual, else its file (the MJCF's asset name)."""
    return Material(name=f"{stem}_material{index}", rgba=rgba)
