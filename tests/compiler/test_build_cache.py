"""A second `mpc compile` of an unchanged definition writes its kept outputs (compiler/
build_cache.py); anything the build depends on that changed makes it build again.

Each test compiles in a cache of its own and counts what the cache did through MPC_CACHE_TRACE:
`keep build` when a build is kept, `reuse build` when its program and robot are taken, `… with
its outputs` when its outputs are, `… for its program` when its program alone is (--force).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mpc.compiler import front_end
from mpc.compiler.driver import Options, Result, compile_model
from mpc.core.blas import user_environment
from mpc.core.diagnostics import Severity, Sink
from tests.conftest import write
from tests.fixtures import ARM_URDF, arm, tetra_stl

SPEC = """
    model:
      robotname: arm
      modelname: arm-model
      input_models:
        arm: {{basefile: arm.urdf}}
      assemble: {{model: arm}}
      export_config:
        - {{type: urdf, mesh_format: stl}}
        - {{type: sdf, mesh_format: stl}}
        - {{type: smurf}}
        {more}
    """
# An attribute URDF does not have: W0401 on every build, kept builds included.
ODD_URDF = ARM_URDF.replace('<origin xyz="0 0 0.4"/>', '<origin xyz="0 0 0.4" scale="2"/>')


@pytest.fixture
def trace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("MPC_CACHE_TRACE", str(tmp_path / "trace"))
    return tmp_path / "trace"


def _model(folder: Path, urdf: str = ODD_URDF, more: str = "") -> Path:
    arm(folder, urdf)
    spec = write(folder / "arm.yml", SPEC.format(more=more))
    _settle()
    return spec


def _settle() -> None:
    """Let the file system's clock pass the files just written: a file changed as a build
    starts may change after it was read, and such a build is not kept."""
    time.sleep(0.05)


def _build(spec: Path, out: Path, trace: Path, sink: Sink | None = None) -> tuple[Result, Sink, list[str]]:
    sink = sink or Sink()
    before = len(_events(trace))
    result = compile_model(spec, sink, Options(out=out))
    return result, sink, _events(trace)[before:]


def _events(trace: Path) -> list[str]:
    lines = trace.read_text().splitlines() if trace.exists() else []
    return [" ".join(line.split()[1:3]) + (" with its outputs" if line.endswith("outputs") else
                                           " for its program" if line.endswith("program") else "")
            for line in lines if " build " in line]


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _said(sink: Sink) -> list[tuple[str, str, str, int, int]]:
    return [(d.severity.value, d.code, d.message, d.span.line, d.span.col) for d in sink.diagnostics]


def test_an_unchanged_definition_writes_its_kept_outputs_and_diagnostics_without_building(
        tmp_path: Path, trace: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _model(tmp_path / "model")
    first, said, events = _build(spec, tmp_path / "out1", trace)
    assert first.out is not None and events == ["keep build"]
    assert [(d[1], d[3]) for d in _said(said)] == [("W0401", 31)]

    def no_front_end(*args: object, **kwargs: object) -> None:
        raise AssertionError("the front end ran")

    monkeypatch.setattr(front_end, "load_program", no_front_end)
    second, again, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs"]
    assert second.out == tmp_path / "out2"
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")
    assert _said(again) == _said(said)
    assert second.program == first.program and second.robot == first.robot  # read when asked


@pytest.mark.parametrize(("force", "heavy", "events"), [
    (False, ["mpc.compiler.schema", "yaml", "lxml", "numpy", "trimesh"], ["reuse build with its outputs"]),
    (True, ["mpc.compiler.schema"], ["reuse build for its program", "keep build"]),
], ids=["warm", "forced"])
def test_a_second_compile_in_a_new_process_imports_no_schema(tmp_path: Path, trace: Path, force: bool,
                                                              heavy: list[str], events: list[str]) -> None:
    """A warm compile imports no schema, YAML, XML or numpy; a forced one (which reads the
    input models and runs the ops anew) no schema and no front end."""
    spec = _model(tmp_path / "model")
    assert _build(spec, tmp_path / "out1", trace)[2] == ["keep build"]
    code = ("import sys; from mpc.cli.main import main; code = main(['compile', *sys.argv[2:]]); "
            "print(sorted(set(sys.modules) & set(sys.argv[1].split(','))), "
            "'mpc.compiler.front_end' in sys.modules); sys.exit(code)")
    args = [",".join(heavy), str(spec), "-o", str(tmp_path / "out2"), *(["--force"] if force else [])]
    # The environment as a user has it: a `main()` run earlier in this process (another test's)
    # set OPENBLAS_NUM_THREADS for itself (core/blas.py), which a child would take for the user's.
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=user_environment(), timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "[] False", trace.read_text()  # the trace says why
    assert _events(trace)[1:] == events
    assert _files(tmp_path / "out2") == _files(tmp_path / "out1")


def test_an_edited_input_model_builds_again(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    urdf = tmp_path / "model/arm.urdf"
    stat = urdf.stat()
    urdf.write_text(ODD_URDF.replace('<mass value="2"/>', '<mass value="3"/>'))  # the same size
    os.utime(urdf, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # and modification time
    _settle()
    result, _, events = _build(spec, tmp_path / "out", trace)
    assert events == ["keep build"]
    assert result.out is not None and '<mass value="3"/>' in (result.out / "urdf/arm.urdf").read_text()


def test_an_edited_definition_builds_again(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    spec.write_text(spec.read_text().replace("robotname: arm", "robotname: limb"))
    _settle()
    result, _, events = _build(spec, tmp_path / "out", trace)
    assert events == ["keep build"]
    assert result.out is not None and (result.out / "urdf/limb.urdf").is_file()


def test_a_changed_mesh_is_written_anew_from_the_kept_model(tmp_path: Path, trace: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    mesh = tetra_stl(tmp_path / "model/meshes/tetra.stl")
    mesh.write_bytes(mesh.read_bytes().replace(b"mpc test tetrahedron", b"mpc test tetrahedra!"))
    _settle()
    monkeypatch.setattr(front_end, "load_program", lambda *a, **k: pytest.fail("the front end ran"))
    result, _, events = _build(spec, tmp_path / "out", trace)
    assert events == ["reuse build", "keep build"]
    assert result.out is not None and (result.out / "meshes/stl/tetra.stl").read_bytes() == mesh.read_bytes()


def test_a_mesh_swapped_for_a_link_out_of_the_model_is_refused_again(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    assert _build(spec, tmp_path / "out", trace)[0].out is not None
    mesh = tmp_path / "model/meshes/tetra.stl"
    secret = tmp_path / "elsewhere/secret.stl"
    secret.parent.mkdir()
    secret.write_bytes(mesh.read_bytes())  # the same bytes: only where it lies changed
    mesh.unlink()
    mesh.symlink_to(secret)
    result, sink, events = _build(spec, tmp_path / "out2", trace)
    assert result.out is None and not (tmp_path / "out2").exists()
    assert "reuse build" not in " ".join(events)
    refused = [d for d in sink.diagnostics if d.code == "E0650"]
    assert len(refused) == 1
    assert refused[0].message.startswith("mesh 'meshes/tetra.stl' in link 'base' is not read")


def test_werror_fails_a_kept_build_that_had_warnings(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    assert _build(spec, tmp_path / "out", trace)[0].out is not None
    before = _files(tmp_path / "out")
    result, sink, _ = _build(spec, tmp_path / "out", trace, Sink(werror=True))
    assert result.out is None and _files(tmp_path / "out") == before
    assert [(d.severity, d.code) for d in sink.diagnostics] == [(Severity.ERROR, "W0401")]


def test_a_damaged_kept_output_is_noticed_and_written_anew(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out1", trace)
    built = _files(tmp_path / "out1")
    kept = next((tmp_path / "cache/builds").glob("*/outputs-*/urdf/arm.urdf"))
    kept.write_text(kept.read_text().replace("arm", "mra"))  # or the output it is a link of
    result, _, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs", "keep build"]
    assert result.out is not None and _files(tmp_path / "out2") == built


def _mesh_model(folder: Path) -> Path:
    """The arm with its mesh copied as it is (URDF: STL) and converted (SDF: OBJ, a mesh entry)."""
    spec = _model(folder)
    spec.write_text(spec.read_text().replace("sdf, mesh_format: stl", "sdf, mesh_format: obj"))
    _settle()
    return spec


def _entry(cache: Path) -> tuple[Path, dict]:
    [entry] = cache.glob("builds/*/entry")
    return entry, json.loads(entry.read_bytes().split(b"\n", 1)[0])


def test_a_kept_build_names_the_meshes_it_copied_and_writes_them_from_there(
        tmp_path: Path, trace: Path) -> None:
    spec = _mesh_model(tmp_path / "model")
    _build(spec, tmp_path / "out1", trace)
    built = _files(tmp_path / "out1")
    _, header = _entry(tmp_path / "cache")
    [obj] = (tmp_path / "cache/meshes").glob("*.obj")
    assert header["outputs"]["copies"] == [["meshes/obj/tetra.obj", str(obj)],
                                           ["meshes/stl/tetra.stl", str(tmp_path / "model/meshes/tetra.stl")]]
    [kept] = (tmp_path / "cache/builds").glob("*/outputs-*")
    assert sorted(_files(kept)) == sorted(k for k in built if not k.startswith("meshes/"))  # no copies
    _, _, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs"] and _files(tmp_path / "out2") == built


def test_a_damaged_mesh_entry_is_not_written_out_by_a_kept_build(tmp_path: Path, trace: Path) -> None:
    spec = _mesh_model(tmp_path / "model")
    _build(spec, tmp_path / "out1", trace)
    built = _files(tmp_path / "out1")
    [obj] = (tmp_path / "cache/meshes").glob("*.obj")
    obj.write_bytes(obj.read_bytes().replace(b"v ", b"w "))  # its size kept
    _, sink, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs", "keep build"]  # built from the kept model
    assert [d.code for d in sink.diagnostics] == ["W0401", "W0650"]  # the entry, computed again
    assert _files(tmp_path / "out2") == built


def test_a_kept_build_reads_no_copy_from_a_file_the_build_did_not_read(tmp_path: Path, trace: Path) -> None:
    """An entry that names another origin for a mesh (one put into the cache by hand) is not
    written out, even when that file holds the same bytes."""
    spec = _mesh_model(tmp_path / "model")
    _build(spec, tmp_path / "out1", trace)
    built = _files(tmp_path / "out1")
    other = tmp_path / "elsewhere.stl"
    shutil.copy(tmp_path / "model/meshes/tetra.stl", other)
    entry, _ = _entry(tmp_path / "cache")
    source = str(tmp_path / "model/meshes/tetra.stl").encode()
    data = entry.read_bytes().replace(source + b'"]]', str(other).encode() + b'"]]')
    assert data != entry.read_bytes()
    entry.write_bytes(data)
    entry.with_name("entry.sha256").write_text(hashlib.sha256(data).hexdigest() + "\n")
    _, _, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs", "keep build"]  # not written out: built
    assert _files(tmp_path / "out2") == built


def test_another_environment_builds_again(tmp_path: Path, trace: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    assert _build(spec, tmp_path / "out", trace)[2] == ["keep build"]
    monkeypatch.setenv("OLDPWD", str(tmp_path))  # a shell's own variable: the same build
    assert _build(spec, tmp_path / "out", trace)[2] == ["reuse build with its outputs"]


def test_a_package_that_appears_earlier_on_the_search_path_builds_again(
        tmp_path: Path, trace: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """ROS_PACKAGE_PATH stays the same; the folders on it do not."""
    first, second = tmp_path / "first", tmp_path / "second"
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{first}:{second}")
    arm(tmp_path / "model", ODD_URDF.replace("meshes/tetra.stl", "package://arm_meshes/tetra.stl"))
    tetra_stl(second / "arm_meshes/tetra.stl")
    spec = write(tmp_path / "model/arm.yml", SPEC.format(more=""))
    _settle()
    assert _build(spec, tmp_path / "out", trace)[2] == ["keep build"]
    nearer = tetra_stl(first / "arm_meshes/tetra.stl")
    nearer.write_bytes(nearer.read_bytes().replace(b"tetrahedron", b"nearer one!"))
    _settle()
    result, _, events = _build(spec, tmp_path / "out", trace)
    assert events == ["keep build"]
    assert result.out is not None
    assert (result.out / "meshes/stl/tetra.stl").read_bytes() == nearer.read_bytes()


def test_outputs_drawn_by_other_programs_are_kept(tmp_path: Path, trace: Path) -> None:
    render = "- {type: render, views: [front], size: [64, 48]}"
    spec = _model(tmp_path / "model", more=f"- {{type: pdf}}\n        {render}")
    first, _, events = _build(spec, tmp_path / "out1", trace)
    assert first.out is not None and events == ["keep build"]
    assert (first.out / "arm.pdf").stat().st_size > 0 and (first.out / "render/zero_front.png").is_file()
    second, _, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build with its outputs"]
    assert second.out is not None and _files(second.out) == _files(first.out)


def test_a_changed_or_installed_program_draws_its_output_again(tmp_path: Path, trace: Path,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    spec = _model(tmp_path / "model", more="- {type: pdf}")
    bin_folder = tmp_path / "bin"
    bin_folder.mkdir()
    monkeypatch.setenv("PATH", str(bin_folder))  # no `dot` on it: W0502, the Graphviz source only
    first, sink, events = _build(spec, tmp_path / "out1", trace)
    assert first.out is not None and events == ["keep build"] and not (first.out / "arm.pdf").exists()
    assert "W0502" in [d.code for d in sink.diagnostics]
    dot = bin_folder / "dot"  # installed: Graphviz's own, run through a script
    dot.write_text(f"#!/bin/sh\nexec {shutil.which('dot', path='/usr/bin:/bin')} \"$@\"\n")
    dot.chmod(0o755)
    _settle()
    second, sink, events = _build(spec, tmp_path / "out2", trace)
    assert events == ["reuse build", "keep build"] and "W0502" not in [d.code for d in sink.diagnostics]
    assert second.out is not None and (second.out / "arm.pdf").read_bytes().startswith(b"%PDF")
    assert _build(spec, tmp_path / "out3", trace)[2] == ["reuse build with its outputs"]
    dot.write_text(dot.read_text() + "# upgraded\n")  # another version of the program
    _settle()
    assert _build(spec, tmp_path / "out4", trace)[2] == ["reuse build", "keep build"]


def test_a_render_depends_on_the_graphics_libraries_that_drew_it(tmp_path: Path) -> None:
    from mpc.backends import render
    from mpc.backends.urdf_reader import read
    from mpc.core.reads import ReadRecorder, recording
    from mpc.core.span import Span
    from mpc.ir.program import RenderExport

    arm(tmp_path)
    robot = read(tmp_path / "arm.urdf", Sink(), None)
    assert robot is not None
    with recording(ReadRecorder()) as recorder:
        render.emit(robot, RenderExport(span=Span("a.yml", 1, 1, 1, 1), views=("front",), size=(32, 24)),
                    tmp_path / "out", Sink())
    assert (tmp_path / "out/render/zero_front.png").is_file()
    drawn_with = [os.path.basename(p) for p in recorder.programs]
    assert any(name.startswith("libEGL_mesa.so") for name in drawn_with), drawn_with
    assert all(not p.startswith(sys.prefix) for p in recorder.programs)


def test_a_build_that_failed_is_not_kept(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model", ODD_URDF.replace('<child link="lower"/>', '<child link="lowr"/>'))
    for out in ("out1", "out2"):
        result, sink, events = _build(spec, tmp_path / out, trace)
        assert result.out is None and events == []
        assert [d.code for d in sink.diagnostics if d.severity is Severity.ERROR] == ["E0411"]


def test_a_branch_of_a_repository_is_fetched_on_every_build(tmp_path: Path, trace: Path) -> None:
    repo = tmp_path / "models"
    arm(repo)
    for args in (["init", "-q", "-b", "main"], ["add", "-A"], ["commit", "-q", "-m", "arm"]):
        subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True,
                       env={**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
                            "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t"})
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm-from-git
          input_models:
            arm: {{repo: {{git: "file://{repo}", branch: main, model_in_repo: arm.urdf}}}}
          assemble: {{model: arm}}
        """)
    _settle()
    for out in ("out1", "out2"):
        result, _, events = _build(spec, tmp_path / out, trace)
        assert result.out is not None and events == []


def test_a_build_whose_files_changed_as_it_ran_is_not_kept(tmp_path: Path, trace: Path) -> None:
    """The file system's clock cannot tell a file changed after the build read it, within the
    same tick, from one changed before: a file dated at the build's start or later is such."""
    spec = _model(tmp_path / "model")
    soon = time.time_ns() + 1_000_000_000
    os.utime(tmp_path / "model/arm.urdf", ns=(soon, soon))
    result, _, events = _build(spec, tmp_path / "out", trace)
    assert result.out is not None and events == []
    os.utime(tmp_path / "model/arm.urdf", ns=(soon - 2_000_000_000, soon - 2_000_000_000))
    _settle()
    assert _build(spec, tmp_path / "out", trace)[2] == ["keep build"]


def test_force_builds_anew_from_the_kept_program_and_keeps_that_build(
        tmp_path: Path, trace: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """--force reads the inputs, runs the ops and writes every output again; the program (what
    the front end made of the unchanged definition) is the kept one, its diagnostics said once."""
    spec = _model(tmp_path / "model")
    first, said, _ = _build(spec, tmp_path / "out1", trace)
    built = _files(tmp_path / "out1")
    (tmp_path / "out1/urdf/arm.urdf").write_text("changed by hand\n")
    (tmp_path / "out1/extra.txt").write_text("not an output\n")

    def no_front_end(*args: object, **kwargs: object) -> None:
        raise AssertionError("the front end ran")

    read = []
    from mpc.compiler import inputs

    parse = inputs.InputLoader._parse
    sink = Sink()
    with monkeypatch.context() as patch:
        patch.setattr(front_end, "load_program", no_front_end)
        patch.setattr(inputs.InputLoader, "_parse", lambda self, path, *a: read.append(path.name)
                      or parse(self, path, *a))
        result = compile_model(spec, sink, Options(out=tmp_path / "out1", force=True))
    assert result.out is not None and _events(trace)[1:] == ["reuse build for its program", "keep build"]
    assert read == ["arm.urdf"]  # the input model, read anew
    assert _files(tmp_path / "out1") == built  # every output written anew, and only those
    assert _said(sink) == _said(said)  # W0401 of the input model, once
    assert result.program == first.program and result.robot == first.robot
    again = Sink()  # from the program the forced build kept: its front end's diagnostics too
    compile_model(spec, again, Options(out=tmp_path / "out1", force=True))
    assert _said(again) == _said(said)
    _, _, events = _build(spec, tmp_path / "out2", trace)  # the build it kept
    assert events == ["reuse build with its outputs"] and _files(tmp_path / "out2") == built


def test_force_keeps_the_kept_copy_of_unchanged_outputs_and_damage_is_found_when_written_out(
        tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    built = _files(tmp_path / "out")
    [kept] = (tmp_path / "cache/builds").glob("*/outputs-*")
    compile_model(spec, Sink(), Options(out=tmp_path / "out", force=True))
    assert list((tmp_path / "cache/builds").glob("*/outputs-*")) == [kept]  # the same files
    urdf = kept / "urdf/arm.urdf"
    urdf.write_text("damaged\n")  # another size: a new copy
    compile_model(spec, Sink(), Options(out=tmp_path / "out", force=True))
    [kept] = (tmp_path / "cache/builds").glob("*/outputs-*")
    assert _files(kept) == {k: v for k, v in built.items() if k != "meshes/stl/tetra.stl"}  # named
    urdf = kept / "urdf/arm.urdf"
    urdf.write_bytes(urdf.read_bytes().upper())  # the same size: kept, and found when written out
    compile_model(spec, Sink(), Options(out=tmp_path / "out", force=True))
    assert list((tmp_path / "cache/builds").glob("*/outputs-*")) == [kept]
    # the damaged copy is not written out: the build runs from the kept model and keeps a new copy
    assert _build(spec, tmp_path / "out2", trace)[2] == ["reuse build with its outputs", "keep build"]
    assert _build(spec, tmp_path / "out3", trace)[2] == ["reuse build with its outputs"]
    assert _files(tmp_path / "out2") == _files(tmp_path / "out3") == built


def test_force_runs_the_front_end_on_a_changed_definition(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    spec.write_text(spec.read_text().replace("robotname: arm", "robotname: limb"))
    _settle()
    result = compile_model(spec, Sink(), Options(out=tmp_path / "out", force=True))
    assert _events(trace)[1:] == ["keep build"]
    assert result.out is not None and sorted(p.name for p in (result.out / "urdf").iterdir()) == ["limb.urdf"]


def test_force_builds_a_derived_base_from_the_kept_program(tmp_path: Path, trace: Path) -> None:
    _model(tmp_path / "model")
    spec = write(tmp_path / "model/derived.yml", """
        model:
          robotname: derived
          modelname: derived-model
          input_models:
            base: {derived_base: arm.yml}
          assemble: {model: base}
          export_config:
            - {type: urdf, mesh_format: stl}
        """)
    _settle()
    first, said, _ = _build(spec, tmp_path / "out1", trace)
    sink = Sink()
    forced = compile_model(spec, sink, Options(out=tmp_path / "out2", force=True))
    assert _events(trace)[1:] == ["reuse build for its program", "keep build"]
    assert forced.robot == first.robot and _files(tmp_path / "out2") == _files(tmp_path / "out1")
    assert _said(sink) == _said(said)


def test_werror_with_force_fails_on_the_kept_programs_warnings(tmp_path: Path, trace: Path) -> None:
    spec = _model(tmp_path / "model")
    _build(spec, tmp_path / "out", trace)
    sink = Sink(werror=True)
    result = compile_model(spec, sink, Options(out=tmp_path / "out2", force=True))
    assert result.out is None and not (tmp_path / "out2").exists()
    assert [(d.severity, d.code) for d in sink.diagnostics] == [(Severity.ERROR, "W0401")]


def test_an_output_folder_that_cannot_be_written_is_said_with_the_kept_build_too(tmp_path: Path,
                                                                                trace: Path) -> None:
    spec = _model(tmp_path / "model")
    assert _build(spec, tmp_path / "out", trace)[2] == ["keep build"]
    (tmp_path / "taken").write_text("a file where the output's folder should be\n")
    result, sink, events = _build(spec, tmp_path / "taken/out", trace)
    assert result.out is None and events == ["reuse build with its outputs"]
    (error,) = [d for d in sink.diagnostics if d.severity is Severity.ERROR]
    assert error.code == "E0660" and error.message.startswith("cannot make the output's folder")
    assert error.message.endswith("; the previous output is unchanged")
