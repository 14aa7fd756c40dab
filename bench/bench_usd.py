"""The usd export beside NVIDIA's `urdf-usd-converter`, on the same example-robot-data robots,
in one run: time per robot, and a table of what each USD holds.

The converter bundles its own USD (usd-exchange's `pxr`), which cannot share an environment
with usd-core: install it in a virtual environment of its own first,

    python3 -m venv /tmp/usdconv-venv
    /tmp/usdconv-venv/bin/pip install urdf-usd-converter==0.3.4

and give its folder with --converter (default /tmp/usdconv-venv).

Times, each robot, the two tools in turns (A B A B …), medians of --runs runs after a warm-up
of each (mpc's mesh cache warm, its build cache not used: `mpc compile --force`):
- whole process: `mpc compile DEF -o OUT --force` (a usd export, the layered layout, and the
  SMURF mpc always writes) against `urdf_usd_converter URDF OUT`; wall and CPU seconds of the
  child processes, and the ratio mpc / converter of each pair;
- in one process: each tool's Python API called again and again in one process of its
  environment (the imports paid once): mpc's `compile_model`, the converter's
  `Converter().convert`;
- the four robots at once, whole processes, as a CI job builds them: one `mpc run PIPELINE -j 1
  --force` (one process, one core) against the converter run once per robot.
The machine is shared: quote the CPU figures and the ratios.

Fidelity: both outputs opened with usd-core here, counted: mimic joints (NewtonMimicAPI or
PhysxMimicJointAPI), drives, joint dynamics (damping, friction, armature), joint velocity
limits, transmissions, coloured materials, collision shapes by kind and mesh approximation,
and the total mass.

Run: python bench/bench_usd.py [--runs N] [--converter VENV]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

from mpc.core.packages import PackageResolver

ROBOTS = ("ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
          "solo_description/robots/solo12.urdf", "talos_data/robots/talos_reduced.urdf")
DEFINITION = """model:
  robotname: {name}
  modelname: {name}
  input_models:
    base: {{basefile: "{urdf}"}}
  assemble: {{model: base}}
  export_config:
    - type: usd
"""
IN_PROCESS_MPC = """
import sys, time, json
from pathlib import Path
from mpc.compiler.driver import Options, compile_model
from mpc.core.diagnostics import Sink
runs, out = int(sys.argv[1]), {}
for definition in sys.argv[2:]:
    times = []
    for i in range(runs + 1):
        start = time.perf_counter()
        out_dir = Path(definition).with_suffix(".inproc")
        r = compile_model(Path(definition), Sink(), Options(out=out_dir, force=True))
        assert r.out is not None
        times.append(time.perf_counter() - start)
    out[definition] = sorted(times[1:])[len(times[1:]) // 2]
print(json.dumps(out))
"""
IN_PROCESS_CONVERTER = """
import sys, time, json, tempfile
from urdf_usd_converter import Converter
runs, out = int(sys.argv[1]), {}
for urdf in sys.argv[2:]:
    times = []
    for i in range(runs + 1):
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            Converter().convert(urdf, folder)
            times.append(time.perf_counter() - start)
    out[urdf] = sorted(times[1:])[len(times[1:]) // 2]
print(json.dumps(out))
"""


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds (user + system, of the child) of one run."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def fidelity(root: Path) -> dict[str, object]:
    """What one USD asset holds (see the module's docstring)."""
    from pxr import Usd, UsdPhysics, UsdShade

    stage = Usd.Stage.Open(str(root))
    counts: Counter[str] = Counter()
    approximations: Counter[str] = Counter()
    colours = set()
    mass = 0.0
    for prim in Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies()):
        listed = prim.GetMetadata("apiSchemas")
        schemas = [str(s) for s in listed.GetAddedOrExplicitItems()] if listed else []
        names = [p.GetName() for p in prim.GetProperties()]
        if prim.IsA(UsdPhysics.Joint):
            counts["joints"] += 1
            counts["mimic"] += any(s.startswith(("NewtonMimicAPI", "PhysxMimicJointAPI")) for s in schemas)
            counts["drives"] += any(s.startswith("PhysicsDriveAPI") for s in schemas)
            counts["dynamics"] += any(k in n.lower() for n in names if "drive" not in n
                                      for k in ("damping", "friction", "armature"))
            counts["velocity limits"] += any("velocity" in n.lower() and "drive" not in n for n in names)
        counts["transmissions"] += any("transmission" in n.lower() for n in names)
        if prim.HasAPI(UsdPhysics.CollisionAPI):
            counts[f"collisions: {prim.GetTypeName()}"] += 1
            if prim.HasAPI(UsdPhysics.MeshCollisionAPI):
                approximations[str(UsdPhysics.MeshCollisionAPI(prim).GetApproximationAttr().Get())] += 1
        if prim.IsA(UsdShade.Shader):  # its colour, or the material's input it is connected to
            colour = UsdShade.Shader(prim).GetInput("diffuseColor")
            values = [a.Get() for a in colour.GetValueProducingAttributes()] if colour else []
            colours.update(tuple(round(c, 4) for c in v) for v in values if v is not None)
        if prim.HasAPI(UsdPhysics.MassAPI):
            mass += UsdPhysics.MassAPI(prim).GetMassAttr().Get() or 0.0
    return {**counts, "colours": len(colours), "approximations": dict(sorted(approximations.items())),
            "mass": round(mass, 6)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--converter", type=Path, default=Path("/tmp/usdconv-venv"))
    parser.add_argument("--fidelity-only", action="store_true", help="convert each robot once, no times")
    args = parser.parse_args()
    tool = args.converter / "bin" / "urdf_usd_converter"
    if not tool.is_file():
        sys.exit(f"no {tool}: create the converter's environment first (see this script's docstring)")
    erd = PackageResolver().find("example-robot-data")
    assert erd is not None, "example-robot-data is not installed"
    mpc = str(Path(sys.executable).with_name("mpc"))
    work = Path(tempfile.mkdtemp(prefix="bench-usd-"))
    env = {**os.environ, "MPC_CACHE_DIR": str(work / "cache")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # users' runs import compiled bytecode (both tools)
    definitions, urdfs = [], []
    print(f"{'robot':16} {'mpc wall':>9} {'conv wall':>9} {'mpc cpu':>8} {'conv cpu':>8} "
          f"{'cpu ratio':>9} {'wall ratio':>10}")
    for rel in ROBOTS:
        urdf = erd / "robots" / rel
        name = urdf.stem
        definition = work / f"{name}.yml"
        definition.write_text(DEFINITION.format(name=name, urdf=urdf))
        definitions.append(str(definition))
        urdfs.append(str(urdf))
        a = [mpc, "compile", str(definition), "-o", str(work / f"{name}.mpc"), "--force"]
        b = [str(tool), str(urdf), str(work / f"{name}.conv")]
        timed(a, env)  # warm-up: fills the mesh cache, compiles bytecode
        timed(b, env)
        if args.fidelity_only:
            continue
        rows = [(timed(a, env), timed(b, env)) for _ in range(args.runs)]
        med = statistics.median
        print(f"{name:16} {med(r[0][0] for r in rows):9.2f} {med(r[1][0] for r in rows):9.2f} "
              f"{med(r[0][1] for r in rows):8.2f} {med(r[1][1] for r in rows):8.2f} "
              f"{med(r[0][1] / r[1][1] for r in rows):9.2f} {med(r[0][0] / r[1][0] for r in rows):10.2f}")
    if args.fidelity_only:
        return fidelities(work, urdfs)
    pipeline = work / "pipeline.yml"
    pipeline.write_text("pipeline:\n  root: .\n  model_definitions:\n"
                        + "".join(f"    - {Path(d).name}\n" for d in definitions))
    run = [mpc, "run", str(pipeline), "-j", "1", "--force", "-o", str(work / "run")]
    timed(run, env)
    fleet = []
    for _ in range(args.runs):
        ours = timed(run, env)
        theirs = [timed([str(tool), urdf, str(work / f"{Path(urdf).stem}.conv")], env) for urdf in urdfs]
        fleet.append((ours, (sum(t[0] for t in theirs), sum(t[1] for t in theirs))))
    med = statistics.median
    print(f"\nthe four at once: mpc run -j 1 wall {med(f[0][0] for f in fleet):.2f} s, cpu "
          f"{med(f[0][1] for f in fleet):.2f} s; the converter four times wall "
          f"{med(f[1][0] for f in fleet):.2f} s, "
          f"cpu {med(f[1][1] for f in fleet):.2f} s; ratio wall {med(f[0][0] / f[1][0] for f in fleet):.2f}, "
          f"cpu {med(f[0][1] / f[1][1] for f in fleet):.2f}")
    mpc_in = json.loads(subprocess.run([sys.executable, "-c", IN_PROCESS_MPC, str(args.runs), *definitions],
                                       env=env, check=True, capture_output=True, text=True).stdout)
    conv_in = json.loads(subprocess.run([str(args.converter / "bin" / "python"), "-c", IN_PROCESS_CONVERTER,
                                         str(args.runs), *urdfs], env=env, check=True, capture_output=True,
                                        text=True).stdout.splitlines()[-1])
    print("\nin one process (imports paid once), median seconds per robot:")
    for definition, urdf in zip(definitions, urdfs, strict=True):
        print(f"{Path(urdf).stem:16} mpc {mpc_in[definition]:6.3f}  converter {conv_in[urdf]:6.3f}  "
              f"ratio {mpc_in[definition] / conv_in[urdf]:5.2f}")
    fidelities(work, urdfs)


def fidelities(work: Path, urdfs: list[str]) -> None:
    print("\nfidelity (counted in each tool's USD):")
    for urdf in urdfs:
        name = Path(urdf).stem
        ours = fidelity(work / f"{name}.mpc" / "usd" / f"{name}.usda")
        theirs = fidelity(next((work / f"{name}.conv").glob("*.usd*")))
        print(f"{name}:")
        for key in sorted(set(ours) | set(theirs)):
            print(f"  {key:28} mpc {ours.get(key, 0)!s:32} converter {theirs.get(key, 0)!s}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
