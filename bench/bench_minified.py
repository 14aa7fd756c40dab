"""A minified URDF (the whole file on one line) against the same URDF pretty-printed, at two
sizes: the time to read it and find the span of every element (what a kept build, the
language server or a diagnostic asks for), and to compile it.

Each element's span was found by searching the line where lxml says its start tag ends: on a
one-line file, the whole file for every element, so time grew with the square of the element
count (issue 29). The span finder (backends/xml.py) now scans a long line's start tags once.
Ten times the elements should take about ten times as long, minified or not.

The URDF is a binary tree of N links (inertial, a box visual, a cylinder collision) and N-1
revolute joints, written by this script (a tree, not a chain: what grows with a chain's depth
is not what this measures); compiled to URDF in a fresh cache. Figures are the best of a
few runs (a loaded machine only slows a run down).

Run: python bench/bench_minified.py [--links 1000 10000] [--runs N]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from mpc.backends import urdf
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Sink

DEFINITION = """model:
  robotname: chain
  modelname: chain-model
  input_models:
    chain: {basefile: chain.urdf}
  assemble: {model: chain}
  export_config:
    - {type: urdf}
"""


def tree(links: int, separator: str) -> str:
    """A URDF of `links` links in a binary tree, its elements joined by `separator` ("": minified)."""
    parts = ['<?xml version="1.0"?>', '<robot name="chain">']
    for i in range(links):
        parts.append(
            f'<link name="l{i}"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
            '<visual><geometry><box size="0.1 0.1 0.2"/></geometry></visual>'
            '<collision><geometry><cylinder radius="0.05" length="0.2"/></geometry></collision></link>')
        if i:
            parts.append(
                f'<joint name="j{i}" type="revolute"><parent link="l{(i - 1) // 2}"/><child link="l{i}"/>'
                '<origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>'
                '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    parts.append("</robot>")
    return separator.join(parts)


def spans(path: Path) -> float:
    """Seconds to read the URDF and find the span of every link, joint and their parts."""
    t0 = time.perf_counter()
    robot = urdf.read(path, Sink())
    assert robot is not None
    for element in [*robot.links.values(), *robot.joints.values()]:
        assert element.span.line >= 1 and element.span.col >= 1
        for part in (*getattr(element, "visuals", ()), *getattr(element, "collisions", ())):
            assert part.span.col >= 1
    return time.perf_counter() - t0


def compile_seconds(folder: Path) -> float:
    """Seconds of one `mpc compile` of the chain's definition in `folder` (a fresh cache)."""
    os.environ["MPC_CACHE_DIR"] = str(folder / f"cache-{time.monotonic_ns()}")
    sink = Sink()
    t0 = time.perf_counter()
    result = compile_model(folder / "chain.yml", sink, Options(out=folder / "out"))
    seconds = time.perf_counter() - t0
    assert result.out is not None, [str(d.message) for d in sink.diagnostics]
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--links", type=int, nargs="+", default=[1000, 10000])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    rows: dict[tuple[str, int], tuple[float, float]] = {}
    with tempfile.TemporaryDirectory(prefix="mpc-bench-minified-") as tmp:
        warm = Path(tmp) / "warm-up"  # imports and first calls, not counted
        warm.mkdir()
        (warm / "chain.urdf").write_text(tree(3, ""))
        (warm / "chain.yml").write_text(DEFINITION)
        compile_seconds(warm)
        for links in args.links:
            for kind, separator in (("minified", ""), ("pretty", "\n")):
                folder = Path(tmp) / f"{kind}-{links}"
                folder.mkdir()
                (folder / "chain.urdf").write_text(tree(links, separator))
                (folder / "chain.yml").write_text(DEFINITION)
                time.sleep(0.05)  # a build of files just written is not kept
                read = min(spans(folder / "chain.urdf") for _ in range(args.runs))
                built = min(compile_seconds(folder) for _ in range(args.runs))
                rows[kind, links] = read, built
                print(f"{kind:8} {links:6} links: read + spans {read:7.3f} s, compile {built:7.3f} s",
                      flush=True)
    small, large = min(args.links), max(args.links)
    if small != large:
        for kind in ("minified", "pretty"):
            (r0, c0), (r1, c1) = rows[kind, small], rows[kind, large]
            print(f"{kind}: {large // small}× the links took {r1 / r0:.1f}× (read + spans), "
                  f"{c1 / c0:.1f}× (compile)")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
