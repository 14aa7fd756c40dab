"""Every place in backends/ that builds a path from data (issue 35.3), listed, so that a new
route from a model's name to a file name cannot be missed.

The scan finds each `/` between non-numbers and each call that makes a path (`confined`,
`joinpath`, `with_name`, `with_suffix`, `Path`, `os.path.join`) in backends/*.py. Each must be
in SITES with why it is safe: a file name made of a model's name goes through core/files.py's
`file_name`, the whole path through `confined`. A new or changed site fails this test until
it is listed (and a stale entry fails it too).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from mpc.core.files import NotAFileName, OutsideOutput, confined, confined_files, file_name

BACKENDS = Path(__file__).resolve().parents[2] / "backends"
PATH_CALLS = {"confined", "confined_files", "joinpath", "with_name", "with_suffix", "Path"}

CONFINED = "confined: names checked (E0250 robotname, filename, file_name, submodel, dirname)"
DATA = "confined, the model's name through file_name (E0540 before any build)"
PASSED = "confined; the name is the one kccd.emit passed through file_name"
READ = "a path that is read, not written (the read-side rule: core/files.py input_problem)"
CACHE = "the cache folder, named by a content hash"
MATH = "arithmetic"
SITES: dict[tuple[str, str, str], str] = {
    ("commands.py", "run", "definition_dir / export.cwd"): "post_processing's cwd (checked by run)",
    ("commands.py", "run", "Path(export.span.file)"): READ,
    ("joint_limits.py", "emit", "confined(out, export.file_name)"): CONFINED,
    ("kccd.py", "emit", "confined(out, export.dirname)"): CONFINED,
    ("kccd.py", "emit", "confined(folder, f'{robot_name}.urdf')"): DATA,
    ("kccd.py", "emit", "confined(out, body.mesh)"): DATA,
    ("kccd.py", "emit", "confined(folder, f'{robot_name}_kccd.yml')"): DATA,
    ("kccd.py", "emit", "confined(out, b.mesh)"): DATA,
    ("kccd.py", "emit", "Path(export.dirname)"): "counts the folders of dirname",
    ("kccd.py", "settings_of", "Path(export.dirname)"): "counts the folders of dirname",
    ("kccd_tools.py", "run_tools", "confined(folder, f'{robot}.cfg')"): PASSED,
    ("kccd_tools.py", "run_tools", "confined(folder, f'{robot}.urdf')"): PASSED,
    ("kccd_tools.py", "_run", "Path(command[0])"): "the tool's name in a message",
    ("mjcf_reader.py", "gather_includes", "Path(name)"): READ,
    ("mjcf_reader.py", "gather_includes", "self.base_dir / name"): READ,
    ("mjcf_reader.py", "gather_meshes", "os.path.join(meshdir, mesh.file)"): READ,
    ("mjcf_reader.py", "gather_meshes", "self.base_dir / uri"): READ,
    ("mjcf_reader.py", "gather_meshes", "os.path.join(spec.modelfiledir, uri)"):
        "the name MuJoCo looks a mesh up by among the files handed to it; no file",
    ("mjcf_reader.py", "gather_other_files", "os.path.join(folder, file)"): READ,
    ("mjcf_reader.py", "gather_other_files", "self.base_dir / uri"): READ,
    ("mjcf_reader.py", "gather_other_files", "os.path.join(spec.modelfiledir, uri)"):
        "the name MuJoCo looks a file up by among the files handed to it; no file",
    ("mjcf_reader.py", "msh_as_stl", "cache_dir('msh') / f'{hashlib.sha256(data).hexdigest()}.stl'"): CACHE,
    ("meshes.py", "copy", "confined_files(out, found)"): "confined: mesh paths mpc makes (meshes/…)",
    ("meshes.py", "copy", "out / rel"): "only whether it is there (a name inside); written through confined",
    ("meshes.py", "_cached_path", "cache_dir('meshes') / f'{digest}{suffix}'"): CACHE,
    ("mesh_worker.py", "note_digests", "Path(entry)"):
        "the worker's answer: the cache entries `_cached_path` named, as keys; nothing is written",
    ("mujoco_meshes.py", "_flat", "centred / size"): MATH,
    ("mesh_fork.py", "beside_a_fork", "Path(entry)"):
        "the forked child's answer: the cache entries `_cached_path` named, as keys; nothing is written",
    ("mjcf.py", "cut_axis", "a / np.linalg.norm(a)"): MATH,
    ("mjcf_actuation.py", "_actuator", "effort / FULL_EFFORT_AT"): MATH,
    ("mjcf.py", "emit", "confined(out, 'mjcf', f'{name}.xml')"): CONFINED,
    ("mjcf.py", "emit", "confined(out, 'mjcf', f'{name}_scene.xml')"): CONFINED,
    ("mjcf.py", "_emit_joint", "np.asarray(axis, dtype=float) / np.linalg.norm(axis)"): MATH,
    ("mjcf.py", "_emit_joint", "(e1 - e1 @ n * n) / np.linalg.norm(e1 - e1 @ n * n)"): MATH,
    ("pdf.py", "emit", "confined(out, f'{name}.pdf.gv')"): CONFINED,
    ("pdf.py", "emit", "confined(out, f'{name}.pdf')"): CONFINED,
    ("render.py", "draw_all", "Path(work)"): "a temporary folder of its own",
    ("render.py", "emit", "confined(out, 'render')"): CONFINED,
    ("render.py", "emit", "confined(folder, name)"): "confined: pose names made safe (file_stem)",
    ("ros_package.py", "emit", "confined(out, 'package.xml')"): CONFINED,
    ("ros_package.py", "emit", "confined(out, 'CMakeLists.txt')"): CONFINED,
    ("ros_package.py", "emit", "confined(out, 'config', name)"): DATA,
    ("scene.py", "frame", "ty * size[0] / size[1]"): MATH,
    ("scene.py", "frame", "np.abs(d @ right) / tx"): MATH,
    ("scene.py", "frame", "np.abs(d @ up) / ty"): MATH,
    ("scene.py", "draw", "0.001 * camera.distance / extent"): MATH,
    ("scene.py", "draw", "10 * camera.distance / extent"): MATH,
    ("scene.py", "build", "workdir / 'scene.xml'"): "a temporary folder of its own",
    ("sdf.py", "emit", "confined(out, 'sdf', 'model.config')"): CONFINED,
    ("sdf.py", "emit", "confined(out, 'sdf', f'{export.filename or robot.name}{suffix}.sdf')"): CONFINED,
    ("smurf.py", "_submechanisms", "Path(robot.submechanisms_file)"): READ,
    ("smurf.py", "emit", "confined(out, 'smurf')"): CONFINED,
    ("smurf.py", "emit", "confined(folder, f'{name}.smurf')"): CONFINED + "; E0515",
    ("smurf.py", "emit", "confined(folder, f'{name}_{category}.yml')"): CONFINED + "; E0515",
    ("smurf_reader.py", "entry_span", "path.parent / listed"): READ,
    ("smurf_reader.py", "entry_span", "Path(listed)"): READ,
    ("smurf_reader.py", "robot", "Path(f)"): READ,
    ("smurf_reader.py", "listed", "self.path.parent / name"): READ,
    ("solid_checks.py", "opened_by", "cache_dir('solids') / f'{h.hexdigest()}.json'"): CACHE,
    ("solid_checks.py", "opened_by", "path.with_name(f'.{path.name}.{os.getpid()}.part')"): CACHE,
    ("urdf.py", "emit", "confined(out, 'urdf', f'{export.filename or robot.name}{suffix}.urdf')"): CONFINED,
    ("usd.py", "emit", "confined(out, 'usd', f'{name}.usda')"): CONFINED,
    ("usd.py", "emit", "confined(out, 'usd', rel)"):
        "confined: the payload's layers, `<filename>_payload/<part>.usda` (filename checked, E0250)",
    ("usd.py", "layers_text", "Sdf.Path('/' + root)"): "a prim path in the layer, not a file",
    ("usd_stage.py", "__init__", "Sdf.Path('/' + unique_identifiers([robot.name])[robot.name])"):
        "a prim path (a valid identifier), not a file",
    ("xacro_reader.py", "expand", "Path(m.history[-1][-1])"): READ,
    ("xacro_reader.py", "_current_file", "Path(stack[-1])"): READ,
    ("xacro_reader.py", "_locate", "Path(file)"): READ,
    ("xacro_guard.py", "check", "Path(path)"): READ,
    ("xacro_guard.py", "guarded", "Path(path)"): READ,
    ("xacro_guard.py", "checked_file", "Path(path)"): READ,
    ("xacro_origins.py", "start_element_handler", "Path(stack[-1])"): READ,
    ("xacro_origins.py", "_recording", "Path(stack[-1])"): READ,
    ("meshes.py", "_sound_mark", "cache_dir('verdicts') / kind"): CACHE,
    ("meshes.py", "_sound_mark", "cache_dir('verdicts') / kind / name"): CACHE,
    ("meshes.py", "key", "Path(mesh.source.uri.removeprefix(GENERATED))"):
        "a made mesh's key (`<link>_joined`); its output path goes through copy's confined",
}


def _number(node: ast.expr) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, int | float)


def path_sites() -> set[tuple[str, str, str]]:
    """(module, function, expression) of each place in backends/ that may build a path."""
    found = set()
    for module in sorted(BACKENDS.glob("*.py")):
        for fn in ast.walk(ast.parse(module.read_text(encoding="utf-8"))):
            if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
                    if not (_number(node.left) or _number(node.right)):
                        found.add((module.name, fn.name, ast.unparse(node)))
                elif isinstance(node, ast.Call):
                    text = ast.unparse(node.func)
                    name = text.rsplit(".", 1)[-1]
                    if name in PATH_CALLS or text == "os.path.join":
                        found.add((module.name, fn.name, ast.unparse(node)))
    return found


def test_every_path_a_backend_builds_is_listed_with_why_it_stays_in_the_output() -> None:
    found = path_sites()
    assert sorted(found - set(SITES)) == [], "a new place builds a path: confine it, then list it"
    assert sorted(set(SITES) - found) == [], "listed, but no longer in backends/"


def test_every_listed_data_site_passes_its_name_through_file_name() -> None:
    """A site listed as DATA builds its name with file_name (here, or in the value it uses)."""
    for (module, function, _), why in SITES.items():
        if why == DATA:
            text = (BACKENDS / module).read_text(encoding="utf-8")
            assert "file_name(" in text, (module, function)


@pytest.mark.parametrize("name", ["../../x", "/abs", "a/b", "..", "", "a\\b"])
def test_file_name_refuses_what_is_not_one_file_name(tmp_path: Path, name: str) -> None:
    with pytest.raises(NotAFileName, match=re.escape(f"the pose name '{name}' cannot be a file name")):
        confined(tmp_path, "config", f"init_positions_{file_name(name, 'pose')}.yml")


def test_file_name_keeps_a_file_name(tmp_path: Path) -> None:
    assert confined(tmp_path, "config", f"x_{file_name('ok.name-1', 'pose')}.yml") == \
        tmp_path / "config" / "x_ok.name-1.yml"


def test_confined_files_judges_each_name_as_confined_does(tmp_path: Path) -> None:
    """Each folder resolved once; a link, in a folder or as the file, judged where it leads."""
    out, outside = tmp_path / "out", tmp_path / "outside"
    (out / "meshes/stl").mkdir(parents=True)
    outside.mkdir()
    (out / "meshes/stl/away.stl").symlink_to(outside / "away.stl")  # dangling, and outside
    (out / "meshes/stl/near.stl").symlink_to(out / "meshes/stl/a.stl")
    (out / "meshes/obj").symlink_to(outside)
    names = ["meshes/stl/a.stl", "meshes/stl/near.stl", "urdf.urdf", "meshes/stl/./b.stl"]
    assert confined_files(out, names) == {name: confined(out, name) for name in names}
    for name in ("meshes/stl/away.stl", "meshes/obj/c.obj", "meshes/../../c.stl", "/c.stl"):
        with pytest.raises(OutsideOutput) as raised:
            confined_files(out, ["meshes/stl/a.stl", name])
        with pytest.raises(OutsideOutput) as expected:
            confined(out, name)
        assert str(raised.value) == str(expected.value)
