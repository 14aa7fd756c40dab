"""ir.Robot → pictures (RGB arrays) drawn headless by MuJoCo's renderer through EGL.

The robot goes through the MJCF backend into a MuJoCo model (meshes as OBJ in a work folder,
through the mesh cache); it is posed by joint values and drawn from a named view, with a camera
that frames every shape drawn. Only kinematics run: inertias are replaced by a unit one, so a
model MuJoCo would refuse to simulate (E0504) is still drawn. It writes no file of its own and
knows no export: backends/render.py and checks/pictures.py decide what to draw and where.

Why EGL: on a CI machine without a display, MuJoCo's EGL context on Debian's software Mesa
(llvmpipe) renders; OSMesa did not on the machines we measured, GLFW needs a display. The
context is made here directly (mujoco.egl), not through MUJOCO_GL, so that a process that
imported mujoco before (the MJCF tests) still renders.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from mpc.backends import meshes
from mpc.backends.dae_colours import coloured
from mpc.backends.mjcf import COLLISION_GROUP, VISUAL_GROUP
from mpc.core.diagnostics import Sink
from mpc.core.heap import give_back
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.program import RENDER_VIEWS
from mpc.ir.rename import rename_robot
from mpc.ir.robot import Inertia, Inertial, Joint, Link, Robot

Geometry = Literal["visual", "collision", "both"]
RGBA = tuple[float, float, float, float]
VIEWS = RENDER_VIEWS
COLLISION_COLOUR = (0.95, 0.55, 0.1)  # collisions: orange, translucent over visuals
COLLISION_ALPHA = 0.4
MARGIN = 1.06  # the frame around the robot, as a factor of the tightest distance
GL_PACKAGES = "libegl1 libgl1-mesa-dri"  # Debian's EGL loader and software Mesa (llvmpipe)


class GLMissing(Exception):
    """No headless OpenGL (EGL) context could be made; the message says why."""


@record(slots=True)
class Camera:
    """MuJoCo's free camera: what it looks at, from how far, from which direction."""

    lookat: tuple[float, float, float]
    distance: float
    azimuth: float
    elevation: float


def _axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The camera's forward, right and up vectors (MuJoCo's convention for a free camera)."""
    a, e = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def frame(points: np.ndarray, view: str, size: tuple[int, int], fovy: float = 45.0) -> Camera:
    """The camera of `view` that shows every point (n×3, world) inside a `size` (w, h) picture:
    it looks at the points' box centre from the least distance at which all fit, with MARGIN."""
    azimuth, elevation = VIEWS[view]
    forward, right, up = _axes(azimuth, elevation)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    d = points - centre
    ty = math.tan(math.radians(fovy) / 2)
    tx = ty * size[0] / size[1]
    depth = d @ forward
    need = np.maximum(np.abs(d @ right) / tx, np.abs(d @ up) / ty) - depth
    distance = max(float(need.max()) * MARGIN, 1e-3)
    return Camera(tuple(float(c) for c in centre), distance, azimuth, elevation)  # type: ignore[arg-type]


def _drawable(robot: Robot, geometry: Geometry) -> Robot:
    """The robot with a unit inertial on every link (only kinematics run, and MuJoCo compiles
    any model's mass properties then: a massless moving link would be refused), and only the
    shapes `geometry` draws: MuJoCo need not read, hull and upload the others' meshes (TALOS's
    collision meshes: a tenth of a picture's time)."""
    unit = Inertial(mass=1.0, inertia=Inertia(ixx=1e-3, ixy=0.0, ixz=0.0, iyy=1e-3, iyz=0.0, izz=1e-3))
    links = {n: replace(link, inertial=unit,
                        visuals=link.visuals if geometry != "collision" else (),
                        collisions=link.collisions if geometry != "visual" else ())
             for n, link in robot.links.items()}
    return replace(robot, links=links)


HIDDEN_GROUP = 5  # a geom group no geometry draws: the robots of a scene not shown (`Scene.only`)


def side_by_side(robots: list[Robot]) -> Robot:
    """Several robots as one, to draw each from one MuJoCo model (a mesh file they share is
    read, compiled and uploaded once): robot i's links and joints named `i/<name>`, its root hung
    from a common root by a fixed joint, and each visual's named material inlined (two robots
    may give one name two colours). `Scene.only(i)` shows robot i alone."""
    links: dict[str, Link] = {"side_by_side": Link(name="side_by_side")}
    joints: dict[str, Joint] = {}
    for i, robot in enumerate(robots):
        def prefixed(name: str, i: int = i) -> str:
            return f"{i}/{name}"

        named = {n: replace(link, visuals=tuple(
            replace(v, inline_material=v.inline_material or robot.materials.get(v.material or ""))
            for v in link.visuals)) for n, link in robot.links.items()}
        one = rename_robot(replace(robot, links=named), link=prefixed, joint=prefixed)
        links.update(one.links)
        joints.update(one.joints)
        joints[f"{i}/"] = Joint(name=f"{i}/", type="fixed", parent="side_by_side", child=one.root)
    return Robot(name=robots[0].name, root="side_by_side", links=links, joints=joints)


def _mesh_files(robot: Robot, workdir: Path, sink: Sink, span: Span) -> dict[Any, str] | None:
    """The robot's meshes in `workdir`: STL files stay STL (MuJoCo reads them fastest, with
    shared vertices), the others become OBJ (MuJoCo reads no DAE); each a file MuJoCo reads
    whole (backends/mujoco_meshes.py); None after an error."""
    as_obj = meshes.plan(robot, "obj", sink, span, mujoco=True)
    as_stl = meshes.plan(robot, "stl", sink, span, mujoco=True)
    if as_obj is None or as_stl is None:
        return None
    files = {k: as_stl[k] if not k[1] and k[0].suffix.lower() == ".stl" else rel for k, rel in as_obj.items()}
    return files if meshes.copy(files, workdir, sink, span, robot, mujoco=True) else None


def _gl_context(width: int, height: int) -> Any:
    """An EGL context (mujoco.egl); GLMissing with the reason when there is none."""
    given = os.environ.get("PYOPENGL_PLATFORM")
    if given not in (None, "egl"):
        raise GLMissing(f"PYOPENGL_PLATFORM is '{given}'; mpc renders through EGL")
    # PyOpenGL reads the variable when it is first imported; it is not left set, since the
    # environment is part of what a build is kept by (compiler/build_cache.py).
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    try:
        from mujoco.egl import GLContext

        ctx = GLContext(width, height)
        ctx.make_current()
    except Exception as e:  # ImportError (no libEGL), RuntimeError / EGLError (no device)
        raise GLMissing(f"{type(e).__name__}: {e}".strip()) from None
    finally:
        if given is None:
            del os.environ["PYOPENGL_PLATFORM"]
    return ctx


class Scene:
    """One robot as a MuJoCo model, ready to be posed and drawn.

    geometry: which shapes are drawn (visual, collision, or both: collisions translucent
    over the visuals). colours: rgba of a link's visuals by link name; `others`: the rgba of
    every other link's visuals (None: their own material colours).
    """

    def __init__(self, model: Any, geometry: Geometry) -> None:
        from mpc.backends.mujoco_module import mujoco

        self.mujoco, self.model, self.geometry = mujoco, model, geometry
        self._gl: tuple[tuple[int, int], Any, Any] | None = None
        self.data = mujoco.MjData(model)
        self.body = [model.body(i).name for i in range(model.nbody)]
        self._shown = np.isin(model.geom_group, self._groups())
        self._group = model.geom_group.copy()
        if geometry != "visual":
            collision = model.geom_group == COLLISION_GROUP
            alpha = COLLISION_ALPHA if geometry == "both" else 1.0
            model.geom_rgba[collision] = (*COLLISION_COLOUR, alpha)

    @classmethod
    def build(cls, robot: Robot, workdir: Path, sink: Sink, span: Span, geometry: Geometry = "visual",
              background: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> Scene | None:
        """The scene of `robot` on a `background` colour (a flat skybox), its meshes written as
        OBJ into `workdir`; None after an error (a mesh that cannot be converted, a model MuJoCo
        refuses: E0571)."""
        from mpc.backends import mjcf
        from mpc.backends.mujoco_module import mujoco, warnings_into

        robot = coloured(_drawable(robot, geometry))
        files = _mesh_files(robot, workdir, sink, span)
        if files is None:
            return None
        text = mjcf.to_string(robot, meshes.namer(files, ""))
        rgb = " ".join(f"{c:.6g}" for c in background)
        sky = (f'  <asset><texture name="mpc_background" type="skybox" builtin="flat" rgb1="{rgb}" '
               f'rgb2="{rgb}" width="8" height="8"/></asset>\n  <worldbody>')
        text = text.replace("  <worldbody>", sky, 1)
        (workdir / "scene.xml").write_text(text, encoding="utf-8")
        said: list[str] = []
        try:
            # Through a spec let go of at once, and without MuJoCo's mesh cache: from_xml_path
            # keeps both, three times the model's memory (TALOS: 120 MB beside a 33 MB model).
            with warnings_into(said):
                spec = mujoco.MjSpec.from_file(str(workdir / "scene.xml"))
                model = spec.compile()
        except ValueError as e:
            sink.error(span, "E0571", f"MuJoCo cannot load robot '{robot.name}' to draw it: {e}")
            return None
        finally:
            spec = None
            mujoco.mj_clearCache(mujoco.mj_getCache())
            give_back()
        for message in dict.fromkeys(said):
            sink.warning(span, "W0571", f"MuJoCo warns about robot '{robot.name}' as it loads it to draw "
                         f"it: {message}")
        return cls(model, geometry)

    def only(self, robot: int) -> None:
        """Draw robot `robot` of a scene of robots side by side (`side_by_side`) alone."""
        m = self.model
        mine = np.array([self.body[b].startswith(f"{robot}/") for b in m.geom_bodyid])
        m.geom_group[:] = np.where(mine, self._group, HIDDEN_GROUP)

    def _groups(self) -> list[int]:
        return {"visual": [VISUAL_GROUP], "collision": [COLLISION_GROUP],
                "both": [VISUAL_GROUP, COLLISION_GROUP]}[self.geometry]

    def colour(self, colours: Mapping[str, RGBA], others: RGBA | None) -> None:
        """Paint the visuals (and in `collision` geometry the collisions) by link."""
        m = self.model
        painted = m.geom_group == (COLLISION_GROUP if self.geometry == "collision" else VISUAL_GROUP)
        for g in np.flatnonzero(painted):
            rgba = colours.get(self.body[m.geom_bodyid[g]], others)
            if rgba is not None:
                m.geom_rgba[g] = rgba

    def pose(self, joints: Mapping[str, float]) -> None:
        """Set the one-degree-of-freedom joints named in `joints` (others at 0), then the
        kinematics; a name the model lacks (a fixed joint) is ignored."""
        m, mj = self.model, self.mujoco
        self.data.qpos[:] = m.qpos0
        for name, value in joints.items():
            j = mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, name)
            if j >= 0 and int(m.jnt_type[j]) in (int(mj.mjtJoint.mjJNT_HINGE), int(mj.mjtJoint.mjJNT_SLIDE)):
                self.data.qpos[m.jnt_qposadr[j]] = value
        mj.mj_kinematics(m, self.data)

    def points(self) -> np.ndarray:
        """The corners (world) of the boxes around every drawn shape, at the current pose;
        the world origin when nothing is drawn."""
        m, d = self.model, self.data
        out = [np.zeros((1, 3))]
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        for g in np.flatnonzero(self._shown):
            centre, half = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
            local = centre + signs * half
            out.append(d.geom_xpos[g] + local @ d.geom_xmat[g].reshape(3, 3).T)
        return np.concatenate(out) if len(out) == 1 else np.concatenate(out[1:])

    def close(self) -> None:
        """Free the GL context, if one was made."""
        if self._gl is not None:
            _, ctx, con = self._gl
            ctx.make_current()
            con.free()
            ctx.free()
            self._gl = None

    def draw(self, camera: Camera, size: tuple[int, int]) -> np.ndarray:
        """The picture (h×w×3 uint8) of the current pose from `camera`."""
        return draw(self, camera, size)


def draw(scene: Scene, camera: Camera, size: tuple[int, int]) -> np.ndarray:
    """Render `scene` offscreen; GLMissing when there is no EGL. The GL context is made once a
    scene and size (making it costs more than a small picture)."""
    mj, m = scene.mujoco, scene.model
    w, h = size
    if scene._gl is None or scene._gl[0] != size:
        scene.close()
        m.vis.global_.offwidth, m.vis.global_.offheight = w, h
        m.vis.headlight.ambient[:] = (0.35, 0.35, 0.35)
        m.vis.headlight.diffuse[:] = (0.65, 0.65, 0.65)
        m.vis.headlight.specular[:] = (0.1, 0.1, 0.1)
        ctx = _gl_context(w, h)
        con = mj.MjrContext(m, mj.mjtFontScale.mjFONTSCALE_100)
        mj.mjr_setBuffer(mj.mjtFramebuffer.mjFB_OFFSCREEN, con)
        scene._gl = (size, ctx, con)
    _, ctx, con = scene._gl
    ctx.make_current()
    extent = max(float(m.stat.extent), 1e-6)
    m.vis.map.znear = 0.001 * camera.distance / extent
    m.vis.map.zfar = 10 * camera.distance / extent
    opt = mj.MjvOption()
    opt.geomgroup[:] = 0
    for group in scene._groups():
        opt.geomgroup[group] = 1
    opt.sitegroup[:] = 0
    cam = mj.MjvCamera()
    cam.type = mj.mjtCamera.mjCAMERA_FREE
    cam.lookat[:], cam.distance = camera.lookat, camera.distance
    cam.azimuth, cam.elevation = camera.azimuth, camera.elevation
    scn = mj.MjvScene(m, maxgeom=max(1000, 2 * m.ngeom))
    mj.mjv_updateScene(m, scene.data, opt, None, cam, mj.mjtCatBit.mjCAT_ALL, scn)
    scn.flags[mj.mjtRndFlag.mjRND_SHADOW] = scn.flags[mj.mjtRndFlag.mjRND_REFLECTION] = 0
    rect = mj.MjrRect(0, 0, w, h)
    mj.mjr_render(rect, scn, con)
    rgb = np.empty((h, w, 3), dtype=np.uint8)
    mj.mjr_readPixels(rgb, None, rect, con)
    return np.flipud(rgb).copy()


def png(rgb: np.ndarray) -> bytes:
    """PNG bytes of a picture: no date, no text chunk, so the same picture gives the same bytes."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    # zlib's level 3: a sixth of level 9's time (TALOS's pictures: 4.6 ms against 28), and no larger
    Image.fromarray(rgb, "RGB").save(buf, format="PNG", optimize=False, compress_level=3)
    return buf.getvalue()


def missing_gl_hint() -> str:
    """What to install when there is no EGL."""
    return (f"install EGL and software OpenGL (Debian: apt-get install {GL_PACKAGES}; "
            "scripts/setup.sh does); a GPU driver's EGL works too")
