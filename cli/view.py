"""`mpc view MODEL`: a local web viewer (viser) of a definition, compiled in memory, or of a
built folder; a slider per movable joint within its limits, the named poses, visual and
collision toggles, link frames, and the compare model as a ghost (`--compare DIR|URL@REF`).

It binds 127.0.0.1 unless told otherwise and serves viser's bundled page: the browser loads
nothing from elsewhere. Nothing is written but the mesh cache and a temporary folder.
"""

from __future__ import annotations

import argparse
import re
import signal
import sys
import tempfile
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mpc.core.diagnostics import Sink
from mpc.core.files import resolved
from mpc.core.span import Span

if TYPE_CHECKING:
    from mpc.ir.robot import Robot

ZERO = "zero"
_COMMIT = re.compile(r"[0-9a-f]{7,40}")


def load_model(path: Path, sink: Sink, package: dict[str, Path] | None = None) -> Robot | None:
    """The robot of a definition (compiled in memory: inputs read, ops run) or of a built
    folder (its URDF, or SDF); None with E0690 or the front end's diagnostics."""
    if path.is_dir():
        return _load_folder(CompareTargetFor(path=path), path, sink)
    if not path.is_file():
        sink.error(Span.of_file(str(path)), "E0690", f"'{path}' is neither a model definition nor a "
                   "built folder")
        return None
    from mpc.compiler.driver import Options
    from mpc.compiler.front_end import InputLoader, load_program
    from mpc.compiler.ops_run import apply
    from mpc.core.packages import PackageResolver

    options = Options(resolver=PackageResolver(package_map=dict(package or {})))
    loader = InputLoader(sink, options, (resolved(path),))
    program = load_program(path, sink, options, loader=loader)
    return apply(program, sink, loader) if program is not None else None


def CompareTargetFor(**kw: Any) -> Any:
    from mpc.ir.program import CompareTarget

    return CompareTarget(span=Span.of_file(str(kw.get("path") or kw.get("git"))), **kw)


def compare_target(text: str) -> Any:
    """`DIR` (an existing folder), or `URL@REF` / `URL` (a git repository at a branch or commit)."""
    if Path(text).exists():
        return CompareTargetFor(path=Path(text))
    url, ref = text, ""
    head, at, tail = text.rpartition("@")
    if at and head and "/" not in tail and ":" not in tail:
        url, ref = head, tail
    if _COMMIT.fullmatch(ref):
        return CompareTargetFor(git=url, commit=ref)
    return CompareTargetFor(git=url, branch=ref)


def _load_folder(target: Any, where: Path | str, sink: Sink, workdir: Path | None = None,
                 code: str = "E0690") -> Robot | None:
    from mpc.checks.models import load_compare

    model, problem = load_compare(target, workdir or Path(tempfile.gettempdir()))
    if model is None:
        sink.error(Span.of_file(str(where)), code, f"cannot show '{where}': {problem}")
        return None
    return model.robot


def serve(robot: Robot, ghost: Robot | None, host: str, port: int, workdir: Path, sink: Sink) -> Any:
    """Start the viewer's server with its scene and GUI; the server, or None after an error."""
    import numpy as np
    import viser

    from mpc.cli.view_scene import add_robot, movable
    from mpc.ir.kinematics import joint_range

    try:
        server = viser.ViserServer(host=host, port=port, label=f"mpc view: {robot.name}", verbose=False)
    except OSError as e:
        sink.error(Span.of_file(robot.name), "E0692", f"cannot serve on {host}:{port}: {e.strerror or e}")
        return None
    span = robot.span or Span.of_file(robot.name)
    main = add_robot(server, robot, "robot", workdir / "robot", sink, span)
    other = add_robot(server, ghost, "compare", workdir / "compare", sink, span, ghost=True) \
        if ghost is not None else None
    if main is None or (ghost is not None and other is None):
        server.stop()
        return None
    centre, radius = main.bounds()
    server.initial_camera.look_at = tuple(float(c) for c in centre)
    server.initial_camera.position = tuple(float(c) for c in centre + radius * np.array([1.6, 1.2, 0.9]))
    server.initial_camera.up = (0.0, 0.0, 1.0)
    q: dict[str, float] = {}
    busy = threading.Lock()

    def redraw() -> None:
        with server.atomic():
            main.pose(q)
            if other is not None:
                other.pose(q)

    gui = server.gui
    with gui.add_folder("Show"):
        visual = gui.add_checkbox("Visual", True)
        collision = gui.add_checkbox("Collision", False)
        frames = gui.add_checkbox("Link frames", False)
        ghost_box = gui.add_checkbox("Compare model (ghost)", other is not None, disabled=other is None)
    visual.on_update(lambda _: main.show(main.visuals, visual.value))
    collision.on_update(lambda _: main.show(main.collisions, collision.value))
    frames.on_update(lambda _: [setattr(f, "show_axes", frames.value) for f in main.frames.values()])
    if other is not None:
        ghost_box.on_update(lambda _: other.show(other.visuals, ghost_box.value))
    poses = [ZERO, *sorted(p for p in robot.poses if p != ZERO)]
    pose = gui.add_dropdown("Pose", poses, initial_value=ZERO)
    sliders: dict[str, Any] = {}
    with gui.add_folder("Joints"):
        for joint in movable(robot):
            low, high = joint_range(joint)
            slider = gui.add_slider(joint.name, min=low, max=high, step=(high - low) / 200,
                                    initial_value=min(max(0.0, low), high))
            sliders[joint.name] = slider
            q[joint.name] = slider.value

            def moved(_: Any, name: str = joint.name, handle: Any = slider) -> None:
                q[name] = float(handle.value)
                if not busy.locked():
                    redraw()

            slider.on_update(moved)

    def chosen(_: Any) -> None:
        values = robot.poses.get(pose.value, {}) if pose.value != ZERO or ZERO in robot.poses else {}
        with busy:
            for name, slider in sliders.items():
                low, high = joint_range(robot.joints[name])
                slider.value = min(max(float(values.get(name, 0.0)), low), high)
                q[name] = float(slider.value)
        redraw()

    pose.on_update(chosen)
    redraw()
    return server


def run(args: argparse.Namespace) -> int:
    """Serve the viewer until interrupted; 1 when the model (or the compare model) cannot be shown."""
    from mpc.core.render import print_diagnostics

    sink = Sink()
    with tempfile.TemporaryDirectory(prefix="mpc-view-") as work:
        robot = load_model(args.model, sink, dict(args.package))
        ghost = None
        if robot is not None and args.compare:
            ghost = _load_folder(compare_target(args.compare), args.compare, sink, Path(work) / "clone",
                                 "E0691")
        server = None
        if robot is not None and not sink.has_errors():
            server = serve(robot, ghost, args.host, args.port, Path(work), sink)
        print_diagnostics(sink.diagnostics, args.format)
        if server is None:
            print(f"error: cannot show '{args.model}'", file=sys.stderr)
            return 1
        print(f"mpc view: http://{args.host}:{server.get_port()}/  (Ctrl-C ends it)", flush=True)
        # Ctrl-C and SIGTERM end it, also where the shell that started it ignores SIGINT
        # (a background job of a script).
        stop = threading.Event()
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, lambda *_: stop.set())
        try:
            while not stop.wait(0.5):
                pass
        finally:
            server.stop()
    return 0
