"""ir.Robot → the kinematic tree as a graph: `<name>.pdf.gv` (Graphviz) and `<name>.pdf`.

Links are boxes; joints are ellipses labelled with their type, axis and origin (and their
mimic), numbers rounded for reading (four significant digits, round-off below 1e-9 as 0);
joints of a submechanism are filled with that submechanism's colour. In a test run
(checks/pictures.py) the links that changed against the release are filled orange, the others
grey, as in the pictures. The PDF is rendered by Graphviz's `dot`; without it the .gv file is
still written and a warning says how to get the PDF.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Collection, Iterable
from pathlib import Path

from mpc.backends.xml import write_path
from mpc.core.diagnostics import Sink
from mpc.core.files import confined
from mpc.core.programs import which
from mpc.ir.program import PdfExport
from mpc.ir.robot import Joint, Robot
from mpc.ir.tree import depth_first

# Fill colours for submechanisms, in order (Graphviz's X11 names, light enough for text).
CHANGED, UNCHANGED = "#f2591a", "#d9d9d9"  # a test run's links: checks/pictures.py's palette
PALETTE = ("lightblue", "palegreen", "lightsalmon", "khaki", "plum", "lightcyan", "peachpuff",
           "lightpink", "wheat", "honeydew", "lavender", "mistyrose")


def _quote(text: str) -> str:
    """A DOT string; line breaks become DOT's centred `\\n`."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def readable(x: float) -> str:
    """A number for reading: four significant digits, round-off (below 1e-9) as 0, no `-0`."""
    if abs(x) < 1e-9:
        return "0"
    return f"{x:.4g}"


def _readable(values: Iterable[float]) -> str:
    return " ".join(readable(float(v)) for v in values)


def _joint_label(joint: Joint) -> str:
    lines = [joint.name, joint.type]
    if joint.type not in ("fixed", "floating"):
        lines.append("axis " + _readable(joint.axis or (1.0, 0.0, 0.0)))
    if joint.origin is not None:
        lines.append("xyz " + _readable(joint.origin.xyz))
        lines.append("rpy " + _readable(joint.origin.rpy))
    if joint.mimic is not None:
        lines.append(f"mimics {joint.mimic.joint}")
    return "\n".join(lines)


def to_gv(robot: Robot, changed: Collection[str] | None = None) -> str:
    """The Graphviz source of the kinematic tree, in the canonical order; with `changed` (a
    test run's changed links) those links filled orange and the others grey."""
    colour: dict[str, str] = {}
    for i, sm in enumerate(robot.submechanisms):
        for key in ("jointnames_spanningtree", "jointnames"):
            for joint in sm.definition.get(key, ()):
                colour.setdefault(str(joint), PALETTE[i % len(PALETTE)])
    out = [f"digraph {_quote(robot.name)} {{", '  rankdir="TB";', '  node [fontsize=10];']
    for joint, link in depth_first(robot):
        fill = "" if changed is None else \
            f', style=filled, fillcolor="{CHANGED if link in changed else UNCHANGED}"'
        out.append(f"  {_quote('link:' + link)} [shape=box, label={_quote(link)}{fill}];")
        if joint is None:
            continue
        style = f', style=filled, fillcolor="{colour[joint.name]}"' if joint.name in colour else ""
        out.append(f"  {_quote('joint:' + joint.name)} [shape=ellipse, label={_quote(_joint_label(joint))}"
                   f"{style}];")
        out.append(f"  {_quote('link:' + joint.parent)} -> {_quote('joint:' + joint.name)};")
        out.append(f"  {_quote('joint:' + joint.name)} -> {_quote('link:' + link)};")
    for name in sorted(robot.cut_joints):
        cut = robot.cut_joints[name]
        out.append(f"  {_quote('link:' + cut.parent)} -> {_quote('link:' + cut.child)} "
                   f'[style=dashed, label={_quote(name + " (loop)")}];')
    out.append("}")
    return "\n".join(out) + "\n"


def render_pdf(gv: str) -> bytes | str:
    """The PDF of a Graphviz source, byte-stable (`_stable`), or why not (no `dot`, or its
    complaint)."""
    dot = which("dot")
    if dot is None:
        return "'dot' (Graphviz) is not installed"
    done = subprocess.run([dot, "-Tpdf"], input=gv.encode(), capture_output=True,
                          env={**os.environ, "TZ": "UTC"})
    if done.returncode != 0:
        return done.stderr.decode(errors="replace").strip() or f"dot exited with {done.returncode}"
    return _stable(done.stdout)


def emit(robot: Robot, export: PdfExport, out: Path, sink: Sink) -> None:
    """Write `<name>.pdf.gv` and, with `dot`, `<name>.pdf` in the export's root folder."""
    name = export.filename or robot.name
    gv = confined(out, f"{name}.pdf.gv")
    text = to_gv(robot)
    write_path(gv, text)
    dot = which("dot")
    if dot is None:
        sink.warning(export.span, "W0502", f"'dot' (Graphviz) is not installed: wrote {gv.name} but "
                     "not the PDF", hint=f"apt-get install graphviz, then: dot -Tpdf {gv.name} -o {name}.pdf")
        return
    pdf = render_pdf(text)
    if isinstance(pdf, str):
        sink.error(export.span, "E0506", f"Graphviz could not render {gv.name}: {pdf}")
        return
    confined(out, f"{name}.pdf").write_bytes(pdf)


def _stable(data: bytes) -> bytes:
    """The PDF made byte-stable: cairo stamps it with the time of rendering (and Debian 12's
    ignores SOURCE_DATE_EPOCH), so the stamp becomes SOURCE_DATE_EPOCH's time, else the epoch.
    The date keeps its length, so the PDF's cross-reference offsets stay right."""
    import re
    import time

    epoch = os.environ.get("SOURCE_DATE_EPOCH", "")
    stamp = time.strftime("D:%Y%m%d%H%M%SZ", time.gmtime(int(epoch) if epoch.isdigit() else 0))
    return re.sub(rb"/CreationDate \(D:\d{14}Z\)", b"/CreationDate (" + stamp.encode() + b")", data)
