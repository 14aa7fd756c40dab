"""One rule for every file mpc reads (issue 35, points 2 and 4; specs/files.md "What mpc reads").

Every file-reading key (a definition's `defaults`, `derived_base`, the `basefile` of each
input format, a mesh of an input URDF, a xacro include, a pipeline entry, `submechanisms_file`,
`test_data_file`) is pointed, in a
project that is a real git work tree, at a secret: `/proc/self/environ` (the environment
holds a canary), a link out of the project, an absolute path, `../` and `file://` (a file
outside the project holding a canary). `mpc check` and `mpc compile` refuse each at its line
(exit 1), and neither canary appears in what they print, in the output or in the cache.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import git
import pytest

from tests.conftest import write
from tests.fixtures import arm
from tests.mpc_command import mpc

FILE_CANARY = "CANARY-FILE-5b1e9d"  # what the secret file holds
ENV_CANARY = "CANARY-ENV-77c0a4"  # what the environment holds (and /proc/self/environ)
HEADER = re.compile(r"^(\S+):(\d+):(\d+): error\[(E\d{4})\]: ", re.M)

# key → the suffix of the secret file it is pointed at (the reader is chosen by it)
KEYS = {"defaults": ".yml", "derived_base": ".yml", "basefile-urdf": ".urdf", "basefile-sdf": ".sdf",
        "basefile-smurf": ".smurf", "basefile-xacro": ".urdf.xacro", "mesh": ".stl",
        "xacro-include": ".xacro", "pipeline-entry": ".yml", "submechanisms_file": ".yml",
        "test_data_file": ".yml"}
ATTACKS = ("proc", "link", "absolute", "dotdot", "file-uri")


def _definition(body: str) -> str:
    return ("model:\n  robotname: arm\n  modelname: arm-model\n" + body +
            "  export_config:\n    - {type: urdf, mesh_format: input_type}\n")


def _input(entry: str) -> str:
    return _definition(f"  input_models:\n    arm:\n      {entry}\n  assemble: {{model: arm}}\n")


def _named(attack: str, project: Path, secret: Path, key: str) -> str:
    """How the key names the secret under `attack`. An input model's format is the suffix of
    the file it resolves to: it names /proc/self/environ through a link with a suffix."""
    if attack == "proc" and key.startswith("basefile"):
        (project / f"environ{KEYS[key]}").symlink_to("/proc/self/environ")
        return f"environ{KEYS[key]}"
    if attack == "proc":
        return "/proc/self/environ"
    if attack == "link":
        link = project / f"linked{''.join(secret.suffixes)}"
        link.symlink_to(secret)
        return link.name
    return {"absolute": str(secret), "dotdot": f"../secret/{secret.name}",
            "file-uri": f"file://{secret}"}[attack]


def _project(tmp_path: Path, key: str, attack: str) -> tuple[Path, list[list[str]]]:
    """The project with the key pointed at the secret; the commands to run in it."""
    project, out = tmp_path / "project", tmp_path / "out"
    git.Repo.init(project)
    secret = write(tmp_path / f"secret/secret{KEYS[key]}", f"{FILE_CANARY}: token\n")
    written = _named(attack, project, secret, key)
    spec = project / "robot.yml"
    if key == "defaults":
        write(spec, f"defaults: {written}\n" + _input("basefile: arm.urdf"))
    elif key == "derived_base":
        write(spec, _input(f"derived_base: {written}"))
    elif key in ("submechanisms_file", "test_data_file"):
        where = "  test:\n    test_data_file" if key == "test_data_file" else "  submechanisms_file"
        write(spec, _input("basefile: arm.urdf") + f"{where}: {written}\n")
    elif key.startswith("basefile"):
        write(spec, _input(f"basefile: {written}"))
    elif key == "mesh":
        arm(project)
        urdf = project / "arm.urdf"
        urdf.write_text(urdf.read_text().replace('filename="meshes/tetra.stl"', f'filename="{written}"'))
        write(spec, _input("basefile: arm.urdf"))
    elif key == "xacro-include":
        arm(project)
        write(project / "arm.urdf.xacro", f'<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
              f'  <xacro:include filename="{written}"/>\n  <link name="base"/>\n</robot>\n')
        write(spec, _input("basefile: arm.urdf.xacro"))
    if key != "mesh":
        arm(project)  # arm.urdf, for the keys that start from it
    if key == "pipeline-entry":
        pipeline = write(project / "pipeline.yml",
                         f"pipeline:\n  root: .\n  model_definitions: [{written}]\n")
        return project, [["check", str(pipeline)]]
    return project, [["check", str(spec)], ["compile", str(spec), "-o", str(out)]]


def _everything_written(*folders: Path) -> str:
    texts = []
    for folder in folders:
        for path in folder.rglob("*") if folder.is_dir() else ():
            if path.is_file() and not path.is_symlink():
                texts.append(path.read_bytes().decode("utf-8", "replace"))
    return "\n".join(texts)


@pytest.mark.parametrize("attack", ATTACKS)
@pytest.mark.parametrize("key", KEYS)
def test_a_file_outside_the_project_is_refused_without_quoting_it(tmp_path: Path, key: str,
                                                                  attack: str) -> None:
    project, commands = _project(tmp_path, key, attack)
    cache = tmp_path / "cache"
    env = {**os.environ, "MPC_CACHE_DIR": str(cache), "DEPLOY_TOKEN": ENV_CANARY}
    for command in commands:
        done = mpc(*command, cwd=project, env=env)
        said = done.stdout + done.stderr
        assert done.returncode == 1, (command, said)
        errors = HEADER.findall(said)
        assert errors, said
        file, line, col, code = errors[0]
        # Located in a file of the project (the key's line), never in the secret.
        assert Path(file).resolve().is_relative_to(project.resolve()), said
        assert int(line) >= 1 and int(col) >= 1
        assert code in _expected(key, attack), said
        for canary in (FILE_CANARY, ENV_CANARY):
            assert canary not in said, (command, said)
            assert canary not in _everything_written(tmp_path / "out", cache), command


def _expected(key: str, attack: str) -> set[str]:
    """The codes a refusal may have: E0650 (the read rule); a `file://` that is no path of
    mpc's for the key (a definition's keys take paths, not URIs) names no file: E0601 (it does
    not exist; E0702 for a test_data_file) or, in a xacro, E0620; a pipeline entry outside its
    root is E0641; an input model that resolves to /proc/self/environ has no format mpc reads
    (E0202)."""
    if key == "pipeline-entry":
        return {"E0641", "E0650"} if attack != "file-uri" else {"E0601"}
    if attack == "proc" and key.startswith("basefile"):
        return {"E0202", "E0650"}
    if attack == "file-uri" and key != "mesh":
        return {"xacro-include": {"E0620"}, "test_data_file": {"E0702"}}.get(key, {"E0601"})
    return {"E0650"}


def test_a_definition_outside_a_git_work_tree_reads_only_its_own_folder(tmp_path: Path) -> None:
    """Without git, the project is the definition's folder: a `defaults` file beside it is
    read, one in the folder above is E0650 at the key, naming the key and the path."""
    write(tmp_path / "above.yml", f"default_model:\n  version: '{FILE_CANARY}'\n")
    write(tmp_path / "robots/beside.yml", "default_model:\n  version: '1.0'\n")
    arm(tmp_path / "robots")
    spec = write(tmp_path / "robots/robot.yml", "defaults: beside.yml\n" + _input("basefile: arm.urdf"))
    assert mpc("check", spec).returncode == 0
    spec.write_text("defaults: ../above.yml\n" + _input("basefile: arm.urdf"))
    done = mpc("check", spec)
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == (
        f"{spec}:1:11: error[E0650]: defaults file '../above.yml' is not read: it is "
        f"'{tmp_path / 'above.yml'}', outside the project and the model's package roots")
    assert FILE_CANARY not in done.stderr


def test_inside_a_git_work_tree_the_whole_tree_is_the_project(tmp_path: Path) -> None:
    """In a git work tree, the definition reads what lies anywhere in the tree."""
    git.Repo.init(tmp_path)
    write(tmp_path / "defaults/common.yml", "default_model:\n  version: '2.0'\n")
    arm(tmp_path / "models")
    spec = write(tmp_path / "robots/robot.yml",
                 "defaults: ../defaults/common.yml\n" + _input("basefile: ../models/arm.urdf"))
    done = mpc("compile", spec, "-o", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == \
        (tmp_path / "models/meshes/tetra.stl").read_bytes()


@pytest.mark.parametrize("command", ["check", "compile"])
def test_a_definition_linked_to_proc_is_not_read(tmp_path: Path, command: str) -> None:
    link = tmp_path / "robot.yml"
    link.symlink_to("/proc/self/environ")
    out = ["-o", str(tmp_path / "out")] if command == "compile" else []
    done = mpc(command, link, *out, env={**os.environ, "DEPLOY_TOKEN": ENV_CANARY})
    assert done.returncode == 1
    assert re.fullmatch(rf"{link}:1:1: error\[E0650\]: '{link}' is not read: it is '/proc/\d+/environ', a "
                        "special file of the system", done.stderr.splitlines()[0])
    assert ENV_CANARY not in done.stdout + done.stderr and not (tmp_path / "out").exists()


def test_a_diagnostic_never_quotes_a_line_of_proc(tmp_path: Path) -> None:
    """The renderer shows source lines only of files the read rule allows: a span in
    /proc/self/environ prints its header line alone."""
    from mpc.core.diagnostics import Diagnostic, Severity
    from mpc.core.render import human
    from mpc.core.span import Span

    os.environ["MPC_TEST_SECRET"] = ENV_CANARY
    try:
        text = human([Diagnostic(Severity.ERROR, "E0203", "m", Span("/proc/self/environ", 1, 1, 1, 5))])
    finally:
        del os.environ["MPC_TEST_SECRET"]
    assert text == "/proc/self/environ:1:1: error[E0203]: m"


def test_a_pipeline_s_folder_is_the_project_of_its_definitions(tmp_path: Path) -> None:
    """Without git, `mpc check pipeline.yml` reads a definition's input beside its folder, in
    the pipeline's folder; alone, the definition may not."""
    arm(tmp_path / "models")
    spec = write(tmp_path / "definitions/arm.yml", _input("basefile: ../models/arm.urdf"))
    pipeline = write(tmp_path / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: "
                     "[definitions/arm.yml]\n")
    done = mpc("check", pipeline)
    assert done.returncode == 0, done.stderr
    done = mpc("check", spec)
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == (
        f"{spec}:6:17: error[E0650]: input model '{tmp_path / 'models/arm.urdf'}' is not read: it is "
        f"'{tmp_path / 'models/arm.urdf'}', outside the project and the model's package roots")
