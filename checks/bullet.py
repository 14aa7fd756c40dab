"""load_in_pybullet: the written URDF loads in real PyBullet (DIRECT mode, the file's inertias).

PyBullet prints from C straight to file descriptors 1 and 2; its console is caught
(checks/console.py) and goes into the protocol.
"""

from __future__ import annotations

from mpc.checks.console import captured_fds
from mpc.checks.protocol import Result, failed, passed
from mpc.checks.registry import Context, register
from mpc.core.heap import give_back
from mpc.ir.program import ModelTest


@register("load_in_pybullet")
def load_in_pybullet(ctx: Context, test: ModelTest) -> Result:
    """`loadURDF` of the compiled URDF in a DIRECT PyBullet, with URDF_USE_INERTIA_FROM_FILE;
    the figure is the number of links PyBullet made, which must be all of them."""
    path = ctx.built.path
    if path.suffix != ".urdf":
        return failed(test.name, f"PyBullet is given a URDF; the model is '{path.name}' (add a urdf export)")
    links = len(ctx.built.robot.links)
    with captured_fds() as log:
        import pybullet  # it prints its build time on import

        client = pybullet.connect(pybullet.DIRECT)
        try:
            body = pybullet.loadURDF(str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                     useFixedBase=True, physicsClientId=client)
            loaded = pybullet.getNumJoints(body, physicsClientId=client) + 1
            error = ""
        except pybullet.error as e:
            loaded, error = 0, str(e)
        finally:
            pybullet.disconnect(client)
            give_back()  # what PyBullet freed (its model of the robot), before the pictures
    console = log[0] if log else ""
    if error:
        lines = [ln.strip() for ln in console.splitlines()]
        hint = next((ln for ln in lines if "cannot" in ln.lower() or "error" in ln.lower()), "")
        reason = f"PyBullet cannot load '{path.name}': {error}" + (f" ({hint})" if hint else "")
        return failed(test.name, reason, log=console)
    if loaded != links:
        return failed(test.name, f"PyBullet made {loaded} links of {links}", figure=float(loaded),
                      unit="links", log=console)
    return passed(test.name, f"loaded '{path.name}' with {loaded} links", figure=float(loaded), unit="links",
                  log=console)
