"""Compare two mpc trees' builds: every output file's bytes and the diagnostics, byte for byte.

    python bench/compare_builds.py OLD_MPC NEW_MPC WORK [--erd N]

OLD_MPC and NEW_MPC are the `mpc` programs of two checkouts (each with its own venv, e.g. a
`git worktree add /tmp/old <commit>` set up with `scripts/setup.sh --dev`). Each compiles,
with a cache of its own and `--force`: the definitions of examples/, the runnable examples of
specs/*.md, and for each example-robot-data URDF (the first N with --erd) a definition that
exports urdf, sdf, mjcf, smurf, joint_limits and pdf. Prints each difference and a summary;
exit status 1 when any build differs. For a refactoring that must change no output.
With --meshes, each example-robot-data URDF has two more definitions that write every mesh
as STL and as OBJ, as it is and mirrored; --only-meshes: those definitions alone.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_EXPORTS = """\
  export_config:
    - {type: urdf}
    - {type: sdf}
    - {type: mjcf}
    - {type: smurf}
    - {type: joint_limits}
    - {type: pdf}
"""
_MESH_EXPORTS = """\
  export_config:
    - {type: urdf, mesh_format: stl}
    - {type: urdf, mesh_format: obj, filename_suffix: _obj}
"""


def erd_definitions(work: Path, limit: int | None, meshes: bool = False,
                    only_meshes: bool = False) -> list[Path]:
    """One definition per example-robot-data URDF, written into `work/erd/` beside a copy of
    the URDF (each tree reads the meshes from its own installed example-robot-data); with
    `meshes`, two more that write every mesh as STL and OBJ, as it is and mirrored (their own
    definitions: a model another export refuses still has its meshes compared)."""
    from mpc.core.packages import PackageResolver

    package = PackageResolver().find("example-robot-data")
    assert package is not None, "example-robot-data is not installed"
    out = []
    for urdf in sorted((package / "robots").rglob("*.urdf"))[:limit]:
        name = urdf.relative_to(package / "robots").with_suffix("").as_posix().replace("/", "__")
        path = work / "erd" / f"{name}.yml"
        path.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(urdf, path.with_suffix(".urdf"))
        head = (f"model:\n  robotname: robot\n  modelname: {name}\n  input_models:\n"
                f"    base:\n      basefile: {name}.urdf\n  assemble:\n    model: base\n")
        path.write_text(head + _EXPORTS)
        if not only_meshes:
            out.append(path)
        if meshes or only_meshes:
            for suffix, text in (("meshes", head), ("mirrored", head + "    mirror: {}\n")):
                path = path.with_name(f"{name}__{suffix}.yml")
                path.write_text(text + _MESH_EXPORTS)
                out.append(path)
    return out


def spec_definitions(work: Path) -> list[Path]:
    """The runnable examples of specs/*.md (tests/test_specs.py: a ```yaml block whose first
    line is `# example: NAME`; pipelines left out), each as NAME.yml in a copy of specs/examples/."""
    folder = work / "specs"
    shutil.copytree(ROOT / "specs/examples", folder, dirs_exist_ok=True)
    out = []
    for page in sorted((ROOT / "specs").glob("*.md")):
        for block in re.findall(r"```yaml\n(.*?)```", page.read_text(), re.DOTALL):
            name = re.fullmatch(r"# example: (\S+)", block.split("\n")[0])
            if name is not None and "# kind: pipeline" not in block:
                (folder / f"{name.group(1)}.yml").write_text(block)
                out.append(folder / f"{name.group(1)}.yml")
    return out


def definitions(work: Path, limit: int | None, meshes: bool = False, only_meshes: bool = False) -> list[Path]:
    if only_meshes:
        return erd_definitions(work, limit, only_meshes=True)
    examples = sorted((ROOT / "examples").glob("*.yml"))
    return [*examples, *spec_definitions(work), *erd_definitions(work, limit, meshes)]


def build(mpc: str, definition: Path, out: Path, cache: Path) -> str:
    """The diagnostics and exit status of one build into `out`, the output folder and the
    environment of `mpc` (its `.venv`) shown as `<out>` and `<venv>`."""
    env = {**os.environ, "MPC_CACHE_DIR": str(cache), "MPC_MESH_WORKERS": "1"}
    command = [mpc, "compile", "--force", "--no-post-processing", "-o", str(out), str(definition)]
    run = subprocess.run(command, capture_output=True, text=True, env=env, cwd=definition.parent)
    text = f"exit {run.returncode}\n--- stdout\n{run.stdout}--- stderr\n{run.stderr}"
    # Each tree reads example-robot-data's meshes from its own environment.
    return text.replace(str(out), "<out>").replace(str(Path(mpc).absolute().parents[1]), "<venv>")


def files(folder: Path) -> dict[str, bytes]:
    if not folder.is_dir():
        return {}
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("work", type=Path)
    parser.add_argument("--erd", type=int, default=None, help="only the first N example-robot-data URDFs")
    parser.add_argument("--meshes", action="store_true", help="convert every example-robot-data mesh too")
    parser.add_argument("--only-meshes", action="store_true", help="only the mesh definitions of --meshes")
    args = parser.parse_args()
    work = args.work.resolve()
    differ = compared = outputs = 0
    for definition in definitions(work, args.erd, args.meshes, args.only_meshes):
        results = []
        for side, mpc in (("old", args.old), ("new", args.new)):
            out = work / side / definition.stem
            results.append((build(mpc, definition, out, work / f"cache-{side}"), files(out)))
        (old_text, old_files), (new_text, new_files) = results
        compared += 1
        outputs += len(new_files)
        problems = [] if old_text == new_text else [f"diagnostics differ:\n{old_text}\n=====\n{new_text}"]
        problems += [f"{name}: {'bytes differ' if name in old_files and name in new_files else 'only in one'}"
                     for name in sorted(set(old_files) | set(new_files))
                     if old_files.get(name) != new_files.get(name)]
        status = "same" if not problems else "DIFFERENT"
        shown = definition.relative_to(ROOT) if definition.is_relative_to(ROOT) else definition.name
        print(f"{status}: {shown} ({len(new_files)} files, {old_text.splitlines()[0]})", flush=True)
        for problem in problems:
            print("  " + problem)
        differ += bool(problems)
    print(f"{compared} definitions, {outputs} output files: {differ} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
