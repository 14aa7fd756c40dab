"""The long fuzz run of issue 17: mutated inputs until a time or case budget runs out.

    python bench/fuzz.py [--minutes 10] [--cases N] [--seed 1]

Each case mutates one input (definition, pipeline file, URDF, SDF, SMURF, an STL, OBJ or DAE
mesh, a symbolic link loop, MJCF inertias; tests/fuzzing.py) with 1–4 hostile edits and runs
`mpc compile` (`mpc run` or `mpc check` for pipelines) in process, one case at a time. Every
file an accepted case wrote is checked: well-formed, finite numbers, and (in batches of
--batch cases) every URDF by check_urdf, one SDF in --sdf-every by `ign sdf -k`. Prints the
cases tried, exit codes by count, cases per kind, outputs checked, and every internal error,
broken invariant (exit 3, a traceback, a file outside `-o`) or invalid output with its
edits; exits 1 if there was any.
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tests.fuzzing import KINDS, MUJOCO_WARNINGS, OPS, TOKENS, Edit, Outputs, Seeds, run_case


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--cases", type=int, default=0, help="stop after N cases (0: the time decides)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--batch", type=int, default=200, help="check the kept URDFs and SDFs every N cases")
    parser.add_argument("--sdf-every", type=int, default=20, help="check one SDF in N with `ign sdf -k`")
    args = parser.parse_args()
    rnd = random.Random(args.seed)
    codes: Counter[int] = Counter()
    kinds: Counter[str] = Counter()
    failures: list[str] = []
    stop = time.monotonic() + args.minutes * 60
    with tempfile.TemporaryDirectory(prefix="mpc-fuzz-") as work:
        seeds = Seeds.make(Path(work))
        base = Path(work) / "a/b/cases"
        base.mkdir(parents=True)
        outputs = Outputs(Path(work) / "kept", sdf_every=args.sdf_every)
        refused: list[str] = []
        n = 0
        while time.monotonic() < stop and (not args.cases or n < args.cases):
            kind = KINDS[n % len(KINDS)]
            edits = [Edit(rnd.choice(OPS), rnd.random(), rnd.randrange(len(TOKENS)))
                     for _ in range(rnd.randint(1, 4))]
            command = "run" if kind == "pipeline" and n % 4 == 0 else (
                "check" if kind == "pipeline" or n % 7 == 0 else "compile")
            n += 1
            kinds[kind] += 1
            try:
                codes[run_case(seeds, base, kind, edits, command, outputs)] += 1
            except AssertionError as e:
                codes[3] += 1
                failures.append(f"{kind} {command} {edits}: {str(e)[:2000]}")
            except Exception as e:
                codes[3] += 1
                failures.append(f"{kind} {command} {edits}: {type(e).__name__}: {e}")
            if n % args.batch == 0:
                refused += outputs.consumers_refuse()
        refused += outputs.consumers_refuse()
    print(f"cases tried: {n}")
    print("exit codes: " + ", ".join(f"{code}: {count}" for code, count in sorted(codes.items())))
    print("cases per kind: " + ", ".join(f"{k}: {c}" for k, c in sorted(kinds.items())))
    print(f"internal errors or broken invariants: {len(failures)}")
    for failure in failures[:20]:
        print("  " + failure)
    print(f"output files checked: {outputs.files}; not well-formed or not finite: {len(outputs.invalid)}; "
          f"refused by check_urdf or ign sdf -k: {len(refused)}")
    for problem in (outputs.invalid + refused)[:20]:
        print("  " + problem)
    print(f"MJCF files MuJoCo loaded with a warning: {len(MUJOCO_WARNINGS)}")
    for warning in MUJOCO_WARNINGS[:5]:
        print("  " + warning)
    return 1 if failures or outputs.invalid or refused else 0


if __name__ == "__main__":
    sys.exit(main())
