"""A xacro model is data, not code (issue 35, point 1; backends/xacro_guard.py).

A corpus of hostile xacro files, each the input model of a definition in a git work tree,
is checked by `mpc check`, compiled by `mpc compile` and opened in `mpc lsp`, with a secret
in the environment and a secret file outside the project: none writes its canary file, no
secret reaches what mpc prints, writes or caches, and each gets a located diagnostic in the
xacro file. What a real model does (hector's quadrotor of example-robot-data, macros,
arguments, `python.*`, `math`) still expands exactly as the xacro command expands it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import git
import pytest

from mpc.backends.xacro_guard import expression_problem
from mpc.backends.xacro_reader import expand
from mpc.core.diagnostics import Sink
from mpc.core.packages import PackageResolver
from tests.conftest import ERD, write
from tests.lsp.client import Client
from tests.mpc_command import mpc

ENV_CANARY = "CANARY-ENV-31f9c2"
FILE_CANARY = "CANARY-FILE-a04d7e"
HEADER = re.compile(r"^(\S+):(\d+):(\d+): error\[(E\d{4})\]: ", re.M)

# name → (the xacro's body, the code of its diagnostic). {pwned}: the canary file a payload
# would write; {secret}: a file outside the project holding FILE_CANARY.
HOSTILE = {
    "comprehension-subclasses": (
        '<link name="${[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == \'Popen\']'
        '[0]([\'touch\', \'{pwned}\'])}"/>', "E0670"),
    "comprehension-globals": (
        '<link name="${[f.__globals__[\'os\'].system(\'touch {pwned}\') for f in [xacro.load_yaml]]}"/>',
        "E0670"),
    "lambda-globals": (
        '<link name="${(lambda f: f.__globals__[\'os\'].system(\'touch {pwned}\'))(xacro.load_yaml)}"/>',
        "E0670"),
    # xacro's `${…}` holds no braces: `%c` makes them
    "format-walks-attributes": (
        '<link name="${(\'%c0.__globals__[os].environ[DEPLOY_TOKEN]%c\' % (123, 125))'
        '.format(xacro.load_yaml)}"/>',
        "E0670"),
    "vars-and-mro": (
        '<link name="${[c for c in python.vars(python.type)[\'__subclasses__\']'
        '(python.type.mro(python.type)[1]) '
        'if \'Popen\' in python.repr(c)][0]([\'touch\', \'{pwned}\'])}"/>', "E0670"),
    "generator-frame": ('<link name="${(x for x in [1]).gi_frame.f_globals}"/>', "E0670"),
    "env": ('<link name="$(env DEPLOY_TOKEN)"/>', "E0671"),
    "optenv": ('<link name="$(optenv DEPLOY_TOKEN none)"/>', "E0671"),
    "env-in-an-expression-string": ('<xacro:property name="t" value="$(env DEPLOY_TOKEN)"/>\n'
                                    '  <link name="${t}"/>', "E0671"),
    "include-etc-passwd": ('<xacro:include filename="/etc/passwd"/>', "E0650"),
    "include-outside": ('<xacro:include filename="{secret}"/>', "E0650"),
    "include-outside-by-dotdot": ('<xacro:include filename="../secret/secret.xacro"/>', "E0650"),
    "load-yaml-proc": ('<link name="${xacro.load_yaml(\'/proc/self/environ\')}"/>', "E0650"),
    "load-yaml-outside": ('<link name="${xacro.load_yaml(\'{secret}\')}"/>', "E0650"),
    "power-tower": ('<link name="${9**9**9}"/>', "E0673"),  # hours of one multiplication
    "terabyte-string": ('<link name="${\'a\' * 10**12}"/>', "E0673"),
}


def _hostile(tmp_path: Path, name: str) -> tuple[Path, Path, Path]:
    """The project with the hostile xacro as its input model: (definition, xacro, canary file)."""
    project, pwned = tmp_path / "project", tmp_path / "pwned"
    git.Repo.init(project)
    secret = write(tmp_path / "secret/secret.xacro", f"{FILE_CANARY}: not xml\n")
    body = HOSTILE[name][0].replace("{pwned}", str(pwned)).replace("{secret}", str(secret))
    xacro = write(project / "robot.urdf.xacro", '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                  f'  {body}\n  <link name="base"/>\n</robot>\n')
    spec = write(project / "robot.yml", """\
        model:
          robotname: r
          modelname: r-model
          input_models:
            r: {basefile: robot.urdf.xacro}
          assemble: {model: r}
          export_config:
            - {type: urdf, mesh_format: input_type}
        """)
    return spec, xacro, pwned


def _written(*folders: Path) -> str:
    return "\n".join(p.read_bytes().decode("utf-8", "replace") for f in folders if f.is_dir()
                     for p in f.rglob("*") if p.is_file())


@pytest.mark.parametrize("name", HOSTILE)
def test_a_hostile_xacro_runs_nothing_and_leaks_nothing(tmp_path: Path, name: str) -> None:
    spec, xacro, pwned = _hostile(tmp_path, name)
    out, cache = tmp_path / "out", tmp_path / "cache"
    env = {**os.environ, "DEPLOY_TOKEN": ENV_CANARY, "MPC_CACHE_DIR": str(cache)}
    for command in (["check", spec], ["compile", spec, "-o", out]):
        done = mpc(*command, cwd=spec.parent, env=env)
        said = done.stdout + done.stderr
        assert done.returncode == 1, said
        file, line, col, code = HEADER.findall(said)[0]
        assert (file, code) == (str(xacro), HOSTILE[name][1]), said
        assert int(line) == 2 and int(col) > 1, said  # at the expression, the variable or the include
        assert not pwned.exists(), "the payload ran"
        for canary in (ENV_CANARY, FILE_CANARY, "root:x:0:0"):
            assert canary not in said
            assert canary not in _written(out, cache)


def test_the_language_server_expands_under_the_same_rules(tmp_path: Path) -> None:
    spec, xacro, pwned = _hostile(tmp_path, "comprehension-subclasses")
    client = Client(env={**os.environ, "DEPLOY_TOKEN": ENV_CANARY, "MPC_CACHE_DIR": str(tmp_path / "cache")},
                    cwd=spec.parent)
    try:
        client.initialize(spec.parent)
        diagnostics = client.diagnostics(client.open(spec), 1)
    finally:
        assert client.close() == 0
    assert [d["code"] for d in diagnostics] == ["E0670"]
    assert not pwned.exists()
    xacro.write_text(xacro.read_text().replace("${[c", "$(env DEPLOY_TOKEN)${[c"))
    client = Client(env={**os.environ, "DEPLOY_TOKEN": ENV_CANARY, "MPC_CACHE_DIR": str(tmp_path / "cache")},
                    cwd=spec.parent)
    try:
        client.initialize(spec.parent)
        diagnostics = client.diagnostics(client.open(spec), 1)
    finally:
        assert client.close() == 0
    assert [d["code"] for d in diagnostics] == ["E0671"] and ENV_CANARY not in str(diagnostics)


@pytest.mark.parametrize(("expression", "why"), [
    ("().__class__", "it reads the attribute '__class__', which leads to Python's internals"),
    ("[x for x in [1] if x.__class__]",
     "it reads the attribute '__class__', which leads to Python's internals"),
    ("[__import__ for _ in [1]]", "it uses the name '__import__'"),
    ("'{0}'.format(1)", "it reads the attribute 'format', which leads to Python's internals"),
    ("python.str.mro()", "it reads the attribute 'mro', which leads to Python's internals"),
    ("(x for x in []).gi_frame", "it reads the attribute 'gi_frame', which leads to Python's internals"),
    ("f'{x._private}'", "it reads the attribute '_private', which leads to Python's internals"),
    ("length * 0.8 + math.pi", None), ("python.sorted(links)[0]", None), ("props.link.mass", None),
    ("'a' if type == 'left' else 'b'", None), ("xacro.arg('x')", None),
])
def test_what_an_expression_may_use(expression: str, why: str | None) -> None:
    assert expression_problem(expression) == why


def test_an_allowed_variable_is_read_and_another_is_named(tmp_path: Path) -> None:
    project = tmp_path / "project"
    git.Repo.init(project)
    write(project / "robot.urdf.xacro", '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
          '  <link name="$(env ROBOT_SIDE)_base"/>\n  <link name="$(optenv ROBOT_TOOL gripper)"/>\n'
          '  <joint name="j" type="fixed"><parent link="$(env ROBOT_SIDE)_base"/>'
          '<child link="$(optenv ROBOT_TOOL gripper)"/></joint>\n</robot>\n')
    spec = write(project / "robot.yml", """\
        model:
          robotname: r
          modelname: r-model
          input_models:
            r: {basefile: robot.urdf.xacro, xacro_env: [ROBOT_SIDE, ROBOT_TOOL]}
          assemble: {model: r}
          export_config:
            - {type: urdf, mesh_format: input_type}
        """)
    env = {**os.environ, "ROBOT_SIDE": "left", "MPC_CACHE_DIR": str(tmp_path / "cache")}
    env.pop("ROBOT_TOOL", None)
    done = mpc("compile", spec, "-o", tmp_path / "out", env=env)
    assert done.returncode == 0, done.stderr
    urdf = (tmp_path / "out/urdf/r.urdf").read_text()
    assert '<link name="left_base"' in urdf and '<link name="gripper"' in urdf
    spec.write_text(spec.read_text().replace("[ROBOT_SIDE, ROBOT_TOOL]", "[ROBOT_TOOL]"))
    done = mpc("check", spec, env=env)
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == (
        f"{project / 'robot.urdf.xacro'}:2:21: error[E0671]: xacro, expanding "
        f"'{project / 'robot.urdf.xacro'}': $(env ROBOT_SIDE) / $(optenv ROBOT_SIDE): the environment "
        "variable 'ROBOT_SIDE' is not read; the input model lists the variables its xacro may read in "
        "`xacro_env`")
    spec.write_text(spec.read_text().replace("xacro_env: [ROBOT_TOOL]", "xacro_env: [ROBOT-TOOL]"))
    done = mpc("check", spec, env=env)
    assert done.returncode == 1
    assert done.stderr.splitlines()[0] == (
        f"{spec}:5:48: error[E0672]: xacro_env entry 1, 'ROBOT-TOOL', is not the name of an environment "
        "variable (letters, digits, '_')")


def test_a_real_xacro_expands_as_the_xacro_command_expands_it(tmp_path: Path) -> None:
    """hector's quadrotor macro (example-robot-data, a package root), included and called."""
    macro = ERD / "hector_description/robots/quadrotor_base.urdf.xacro"
    model = write(tmp_path / "hector.urdf.xacro", '<robot name="hector" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                  f'  <xacro:include filename="{macro}"/>\n  <xacro:quadrotor_base_macro/>\n</robot>\n')
    command = subprocess.run([str(Path(sys.executable).parent / "xacro"), str(model)], capture_output=True,
                             text=True, check=True).stdout
    banner = [line for line in command.splitlines() if line.startswith("<!-- ")][:4]
    sink = Sink()
    ours = expand(model, sink, PackageResolver())
    assert [d.code for d in sink.diagnostics] == ["W0623"]  # "redefining global symbol: pi", as xacro says
    assert ours is not None and "<mass value=\"1.477\"/>" in ours
    assert ours.splitlines() == [line for line in command.splitlines() if line not in banner]


@pytest.mark.parametrize("name", ["env", "comprehension-globals", "include-outside"])
def test_mpc_run_keeps_no_secret_in_its_state_or_log(tmp_path: Path, name: str) -> None:
    """`mpc run` of a pipeline whose model is hostile: the model fails with the refusal, the
    payload does not run, and no secret is in its log, its state files or the build."""
    spec, _, pwned = _hostile(tmp_path, name)
    pipeline = write(spec.parent / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [robot.yml]\n")
    cache = tmp_path / "cache"
    done = mpc("run", pipeline, cwd=spec.parent,
               env={**os.environ, "DEPLOY_TOKEN": ENV_CANARY, "MPC_CACHE_DIR": str(cache)})
    said = done.stdout + done.stderr
    assert done.returncode == 1, said
    assert f"error[{HOSTILE[name][1]}]" in said
    assert not pwned.exists()
    for canary in (ENV_CANARY, FILE_CANARY):
        assert canary not in said
        assert canary not in _written(spec.parent, cache)
