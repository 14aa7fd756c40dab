"""`mpc diff OLD NEW`: the semantic changes between two models (checks/diff_models.py), as
text, Markdown or JSON, with `--pictures DIR` the old/new overlay renders.

Exit status as diff's: 0 nothing changed beyond the tolerances, 1 something did, 2 trouble
(a bad command line, a side that cannot be read or compiled: its diagnostics on stderr).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from mpc.cli.output import print_diagnostics

FORMATS = ("human", "markdown", "json")


def _tolerance(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got '{text}'") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected a number ≥ 0, got '{text}'")
    return value


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("old", metavar="OLD", help="the old model: a model file (URDF, SDF, SMURF), a built "
                   "output folder or a definition, each also as PATH@REVISION (git)")
    p.add_argument("new", metavar="NEW", help="the new model, as OLD")
    p.add_argument("--format", choices=FORMATS, default="human", help="how to print the changes "
                   "(default: human)")
    p.add_argument("--pictures", type=Path, metavar="DIR",
                   help="write the old, new and overlay renders, the changed links coloured, into DIR")
    for name, what in (("mass", "masses (kg)"), ("distance", "lengths and positions (m)"),
                       ("rad", "angles (rad)"), ("default", "everything else, and relative for "
                                                 "principal moments of inertia")):
        p.add_argument(f"--{name}", type=_tolerance, metavar="X",
                       help=f"tolerance of {what} (default: mpc test's)")


def run(args: argparse.Namespace) -> int:
    from mpc.checks import diff_report
    from mpc.checks.diff_models import diff
    from mpc.checks.diff_sides import BadSide, load_side
    from mpc.core.diagnostics import Sink
    from mpc.ir.program import Tolerances

    given = {k: getattr(args, k) for k in ("mass", "distance", "rad", "default")}
    tol = Tolerances(**{k: v for k, v in given.items() if v is not None})
    sink = Sink()
    with tempfile.TemporaryDirectory(prefix="mpc-diff-") as work:
        try:
            old = load_side(args.old, sink, Path(work))
            new = load_side(args.new, sink, Path(work)) if old is not None else None
        except BadSide as e:
            print(f"mpc diff: error: {e}", file=sys.stderr)
            return 2
        if old is None or new is None or sink.has_errors():
            print_diagnostics(sink, "human")
            return 2
        d = diff(old.robot, new.robot, tol)
        try:
            pictures = _pictures(args.pictures, old.robot, new.robot, d, tol, sink) if args.pictures else {}
        except OSError as e:
            from mpc.core.files import describe

            print(f"mpc diff: error: cannot write the pictures into '{args.pictures}' ({describe(e)})",
                  file=sys.stderr)
            return 2
    paths = [p for view in pictures.values() for p in view]
    print_diagnostics(sink, "human")
    if args.format == "json":
        print(diff_report.as_json(d, old.label, new.label, tol, paths), end="")
    elif args.format == "markdown":
        print(diff_report.markdown(d, old.label, new.label, tol, pictures), end="")
    else:
        print(diff_report.human(d, old.label, new.label, tol), end="")
    return 1 if d.changed else 0


def _pictures(folder: Path, old: object, new: object, d: object, tol: object,
              sink: object) -> dict[str, list[str]]:
    """The renders written into `folder`: {view: the paths of its old, new and overlay pictures}."""
    from mpc.checks.diff_models import changed_links
    from mpc.checks.pictures import SIDES, draw

    drawn = draw(old, new, tol, None, sink, changed=changed_links(d, old, new))  # type: ignore[arg-type]
    if not drawn.drawn:
        return {}
    folder.mkdir(parents=True, exist_ok=True)
    out: dict[str, list[str]] = {}
    for view in drawn.views:
        for side in SIDES:
            name = f"{view}_{side}.png"
            (folder / name).write_bytes(drawn.files[name])
            out.setdefault(view, []).append((folder / name).as_posix())
    return out
