"""`mpc lsp` on a TALOS-size definition: the latency from an edit to its diagnostics (median and
p95 over 50 edits), and the memory of a server holding TALOS.

The definition is TALOS (example-robot-data) with an entry for each of its joints (limits),
a pose of all of them, renamed links and collision edits: every keystroke is checked against
its names, as in an editor. Each edit is a full-text change; the time runs from sending it
until its diagnostics arrive (the server's debounce included). Goals: median ≤ 30 ms (issue 20),
p95 ≤ 20 ms (issue 34.6), and the server holding TALOS at most 40 MiB (VmRSS, issue 34.6).

Also the memory of 40 TALOS models held in the server's model cache (compiler/options.py
ModelCache, read as the server reads them): what the process grows by (VmRSS) once they are
read, the parsed files freed. Goal (issue 30): ≤ 20 MiB (76 MiB while each kept its parse).
Run: python bench/bench_lsp.py [edits]
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from lxml import etree

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mpc.core.packages import PackageResolver  # noqa: E402
from tests.lsp.client import Client  # noqa: E402

TALOS = "robots/talos_data/robots/talos_full_v2.urdf"


def definition(urdf: Path) -> str:
    """A definition that edits every joint of TALOS and poses all of them."""
    tree = etree.parse(str(urdf))
    joints = [j.get("name") for j in tree.iter("joint") if j.get("type") in ("revolute", "prismatic")]
    links = [link.get("name") for link in tree.iter("link")]
    out = ["model:", "  robotname: talos", "  modelname: talos-edited", "  input_models:", "    talos:",
           f"      basefile: package://example-robot-data/{TALOS}", "  assemble:", "    model: talos",
           "  frames:"]
    for link in links[:10]:
        out += [f"    {link}:", "      name_editing:", "        suffix: _renamed"]
    out.append("  joints:")
    for joint in joints:
        out += [f"    {joint}:", "      min: [deg, -90]", "      max: [deg, 90]", "      eff: 100",
                "      vel: 2*pi", "      damping: 0.5"]
    out.append("  collisions:")
    for link in links[10:30]:
        out += [f"    {link}:", "      shape: box"]
    out += ["  poses:", "    init:"] + [f"      {joint}: [deg, 10]" for joint in joints]
    out += ["  export_config:", "    - type: urdf", "      mesh_format: stl", ""]
    return "\n".join(out)


def memory_kb(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def cpu_seconds(pid: int) -> float:
    """User and system time of a process so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def held_models_mib(urdf: Path, count: int = 40) -> float:
    """What `count` TALOS models held in a ModelCache take (the growth of this process's VmRSS),
    each read as the server reads an input model. One read first, so that imports and the
    readers' one-time set-up are not counted."""
    import gc

    from mpc.backends import urdf_reader
    from mpc.compiler.options import ModelCache
    from mpc.core.diagnostics import Sink

    urdf_reader.read(urdf, Sink())
    cache = ModelCache()
    gc.collect()
    before = memory_kb(os.getpid())
    for i in range(count):  # one entry each: the cache keys a model by its file and xacro args
        cache.read(urdf, (("copy", str(i)),), Sink(), lambda sink: urdf_reader.read(urdf, sink))
    gc.collect()
    assert len(cache) == count, f"the cache keeps {len(cache)} of {count} models"
    return (memory_kb(os.getpid()) - before) / 1024


def main(edits: int = 50) -> None:
    urdf = PackageResolver().find("example-robot-data") / TALOS
    held = held_models_mib(urdf)
    with tempfile.TemporaryDirectory(prefix="mpc-bench-lsp-") as work:
        path = Path(work) / "talos.yml"
        text = definition(urdf)
        path.write_text(text, encoding="utf-8")
        client = Client()
        try:
            client.initialize(Path(work))
            started = time.perf_counter()
            uri = client.open(path)
            first = client.diagnostics(uri, 1)
            opened = time.perf_counter() - started
            times = []
            lines = text.split("\n")
            cpu = cpu_seconds(client.proc.pid)
            damping = max(i for i, line in enumerate(lines) if line.startswith("      damping:"))
            for version in range(2, edits + 2):  # type a joint's damping, one digit at a time
                lines[damping] = f"      damping: 0.{version}"
                sent = time.perf_counter()
                client.change(uri, version, "\n".join(lines))
                arrived, _ = client.published_at(uri, version)
                times.append((arrived - sent) * 1000)
            cpu = cpu_seconds(client.proc.pid) - cpu
            rss = memory_kb(client.proc.pid)
        finally:
            client.close()
    times.sort()
    p95 = times[min(len(times) - 1, round(0.95 * len(times)) - 1)]
    print(f"definition: {len(text.splitlines())} lines, {len(first)} diagnostics on open "
          f"(open and first check: {opened * 1000:.0f} ms)")
    print(f"edit → diagnostics over {edits} edits: median {statistics.median(times):.1f} ms, "
          f"p95 {p95:.1f} ms (goal ≤ 20 ms), min {times[0]:.1f} ms, max {times[-1]:.1f} ms")
    print(f"the server's CPU time per edit: {cpu / edits * 1000:.1f} ms (what the latency is on an idle "
          f"machine, less the debounce; load average now {os.getloadavg()[0]:.1f})")
    print(f"server memory holding TALOS: {rss / 1024:.1f} MiB (VmRSS; goal ≤ 40 MiB)")
    print(f"40 TALOS models held in the model cache: {held:.1f} MiB (goal ≤ 20 MiB)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
