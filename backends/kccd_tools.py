"""The KCCD tools: urdf2kccd turns the KCCD URDF into `<robot>.cfg` and `<robot>Kinematics.cfg`;
kccdcoveriv fits each body's volume with points. mpc runs them when they are on PATH
(argument lists, no shell) and writes the settings into the `.cfg` as Phobos does;
without urdf2kccd it says what is missing (W0520) and keeps what the tools would read.

This path cannot be tested here: neither tool is packaged for Debian or PyPI. It follows
Phobos's use of them: `urdf2kccd -b <robot>.urdf` in the KCCD folder; in the `.cfg`, the
settings appended to the TITLE block, the BRAKINGMODEL template filled in, OVERWRITE lines
for simplify_swept_from, each BODY block's points replaced by `kccdcoveriv <mesh> <n>
<body>`'s fitted volume, and DONTCHECK lines for the pairs not to check.
"""

from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any

from mpc.backends.xml import write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.core.programs import which
from mpc.ir.program import KccdExport


def run_tools(folder: Path, robot: str, settings: dict[str, Any], export: KccdExport,
              stls: list[Path], sink: Sink) -> None:
    """Run urdf2kccd and kccdcoveriv in `folder` if installed; then drop the STL hulls and
    the URDF unless keep_stls / keep_urdf (only then: without the tools they are the output)."""
    urdf2kccd = which("urdf2kccd")
    if urdf2kccd is None:
        sink.warning(export.span, "W0520", f"urdf2kccd is not on PATH: wrote the hulls, {export.dirname}/"
                     f"{robot}.urdf and {export.dirname}/{robot}_kccd.yml; urdf2kccd would have made "
                     f"{export.dirname}/{robot}.cfg and {robot}Kinematics.cfg from them, and kccdcoveriv "
                     "each body's fitted volume", hint="install KCCD's tools and build again")
        return
    if not _run(export, [urdf2kccd, "-b", f"{robot}.urdf"], folder, sink):
        return
    cfg = confined(folder, f"{robot}.cfg")
    if not cfg.is_file():
        sink.error(export.span, "E0520", f"urdf2kccd did not write {export.dirname}/{robot}.cfg")
        return
    text = configured(cfg.read_text(encoding="utf-8"), settings, export, folder, sink)
    if text is None:
        return
    write_path(cfg, text)
    if not export.keep_stls:
        for stl in stls:
            stl.unlink(missing_ok=True)
    if not export.keep_urdf:
        confined(folder, f"{robot}.urdf").unlink(missing_ok=True)


def _run(export: KccdExport, command: list[str], folder: Path, sink: Sink) -> str | None:
    """The output of `command` run in `folder`; None with E0520 when it fails."""
    try:
        done = subprocess.run(command, cwd=folder, capture_output=True, text=True, check=False)
    except OSError as e:
        sink.error(export.span, "E0520", f"cannot run {Path(command[0]).name}: {e.strerror}")
        return None
    if done.returncode != 0:
        tail = (done.stdout + done.stderr).strip().splitlines()[-10:]
        sink.error(export.span, "E0520", f"{Path(command[0]).name} failed with exit code "
                   f"{done.returncode}: " + " / ".join(tail))
        return None
    return done.stdout


def configured(cfg: str, settings: dict[str, Any], export: KccdExport, folder: Path,
                sink: Sink) -> str | None:
    """urdf2kccd's `.cfg` with the settings written in, block by block (blank-line separated)."""
    n_points = {b["link"]: b["n_points"] for b in settings["bodies"]}
    body_names: dict[str, str] = {}
    blocks = []
    for block in cfg.split("\n\n"):
        if "TITLE" in block:
            block += "".join(f"\n{word} {settings[key]}" for word, key in (
                ("SAFETYDISTANCE", "safety_distance"), ("REPORTUPTO", "report_up_to"),
                ("COMPUTATIONBUDGET", "computation_budget"),
                ("MAXAPPROXIMATIONORDER", "max_approximation_order")))
        elif "# BRAKINGMODEL" in block and "braking_model" in settings:
            b = settings["braking_model"]
            block = block.replace("# BRAKINGMODEL", "BRAKINGMODEL")
            for key in ("linearFactor", "invDeceleration", "uncertainty", "latency"):
                block = block.replace(f"<{key}>", str(b[key]))
        elif "# OVERWRITE" in block and settings.get("order_0_joints"):
            for joints in settings["order_0_joints"].values():
                if joints:
                    block += "\nOVERWRITE " + " ".join(joints) + " WITH ORDER 0 END"
        elif block.startswith("BODY "):
            words = block.split()
            body, mesh = words[1], words[8]
            link = body[2:]  # urdf2kccd names a link's body with a two-letter prefix
            body_names[link] = body
            covering = which("kccdcoveriv")
            if covering is not None and link in n_points:
                out = _run(export, [covering, mesh, str(n_points[link]), body], folder, sink)
                if out is None:
                    return None
                kept = [line for line in block.split("\n")
                        if not line.startswith(("BODYRADIUS", "BODYPOINT"))]
                block = "\n".join(kept).strip() + "\n" + out[out.find("# Fitted volume"):].strip()
        blocks.append(block.strip() + "\n\n")
    if which("kccdcoveriv") is None:
        sink.warning(export.span, "W0520", "kccdcoveriv is not on PATH: the bodies keep the points "
                     "urdf2kccd gave them, without a fitted volume")
    for a, b in settings["dont_check"]:
        if a in body_names and b in body_names:
            blocks.append(f"DONTCHECK {body_names[a]} WITH {body_names[b]} END\n")
    return "\n" + "".join(blocks).replace("../../", "../")
