"""Mutated inputs → one mpc run each, checked: exit 0 or 1, no traceback, nothing written
outside `-o` (and mpc's cache). Shared by the bounded Hypothesis suite (tests/test_fuzz.py)
and the long run (bench/fuzz.py); neither decides how many cases to try, this module does
not either.

A case is a seed input (a definition, a pipeline file, a URDF, an SDF, a SMURF or a xacro
file that mpc reads well) and a list of edits; each edit puts a hostile token (`../`, an
absolute path, a NUL, an alias loop, a 300-character name, an entity, a link to /proc, a
xacro expression that reaches for Python or the environment…) at a place in the text,
deletes, repeats or cuts it. A secret in the environment must reach no message and no output.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from tests.conftest import definition
from tests.fixtures import arm

KINDS = ("definition", "pipeline", "urdf", "sdf", "smurf", "xacro")
ESCAPE = "MPCFUZZESCAPE"  # any file with this name outside the case folder is an escape
ABSOLUTE = f"/tmp/{ESCAPE}"
SECRET = "MPCFUZZ_SECRET_4e1b"  # the value of MPC_FUZZ_SECRET while a case runs

# Tokens an edit may write; chosen to hit each class of issue 17 and the parsers' limits.
TOKENS = (
    f"../../{ESCAPE}", f"../{ESCAPE}/x", ABSOLUTE, f"{ABSOLUTE}/y", "a" * 300, "b/" * 130,
    "\x00", "a\x00b", "\x07", "\x1b[2J", '"\\0"', "&x [*x]", "&y {k: *y}", "*nope", "[" * 1500,
    "{" * 1500, "9" * 5000, "0x" + "f" * 400, "1e999", "-.inf", ".nan", "!!python/object:os.system",
    "!custom", "<<: *nope", "? [a, b]\n: c", "~", "", " ", "\t", ":", "- ", "'", '"', "#",
    "é" * 100, "\ufeff", "\u202e", "file:///proc/self/environ", "/proc/self/environ",
    "package://nope/m.stl", "/dev/zero", "/etc/passwd", "meshes/../../../etc/passwd",
    '<!DOCTYPE r [<!ENTITY e "x">]>', "&e;", '<!ENTITY % p SYSTEM "http://127.0.0.1:9/x">',
    "<![CDATA[", "]]>", "<", ">", "&", "</robot>", "<gazebo>", 'name=""', 'xmlns:x="u"',
    "-1", "0", "1e308", "nan", "-0", "3.4.5",
    # issue 35: a xacro that runs code, reads the environment or a system file
    "${().__class__.__base__.__subclasses__()}",
    "${[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'Popen'][0]"
    f"(['touch', '{ABSOLUTE}'])}}",
    f"${{[f.__globals__['os'].system('touch {ABSOLUTE}') for f in [xacro.load_yaml]]}}",
    "$(env MPC_FUZZ_SECRET)", "$(optenv MPC_FUZZ_SECRET)", "${xacro.load_yaml('/proc/self/environ')}",
    '<xacro:include filename="/etc/passwd"/>', '<xacro:include filename="/proc/self/environ"/>',
)


# The exports of the seeds, with the routes from a name to a file name (issue 35.3): a ROS
# package writes each pose as config/init_positions_<pose>.yml, kccd each link's hull as
# meshes/iv/collision_<link>.stl; the poses give a mutation a pose name to hit.
ROUTES = ("      ros_pathes: true\n    - type: sdf\n      mesh_format: stl\n    - type: kccd\n"
          "  ros_pkg_name: robot_model\n  poses:\n    init:\n      shoulder: 0.1\n")


@dataclass(frozen=True)
class Edit:
    """One change of a seed: `op` (value, insert, replace, delete, repeat, cut) at `where` (a
    fraction of the text's length), with `token` (an index into TOKENS)."""

    op: str
    where: float
    token: int


OPS = ("value", "value", "value", "insert", "replace", "delete", "repeat", "cut")


def mutate(text: str, edits: list[Edit]) -> str:
    for e in edits:
        at = int(e.where * len(text))
        token = TOKENS[e.token % len(TOKENS)]
        end = text.find("\n", at)
        end = len(text) if end < 0 else end
        if e.op == "value":  # the next YAML value or XML attribute value: the structure stays
            text = _replace_value(text, at, token)
        elif e.op == "insert":
            text = text[:at] + token + text[at:]
        elif e.op == "replace":  # the rest of the line: usually a value
            text = text[:at] + token + text[end:]
        elif e.op == "delete":
            text = text[:at] + text[end + 1:]
        elif e.op == "repeat":
            start = text.rfind("\n", 0, at) + 1
            text = text[:end] + "\n" + text[start:end] + text[end:]
        else:
            text = text[:at]
    return text


def _replace_value(text: str, at: int, token: str) -> str:
    attr, key = text.find('="', at), text.find(": ", at)
    if attr >= 0 and (key < 0 or attr < key):
        start = attr + 2
        end = text.find('"', start)
    elif key >= 0:
        start = key + 2
        end = text.find("\n", start)
    else:
        return text
    end = len(text) if end < 0 else end
    return text[:start] + token + text[end:]


@dataclass
class Seeds:
    """The files of a small, valid project: the arm, a definition, a pipeline file, and
    the arm's SDF and SMURF as mpc writes them (the inputs the SDF and SMURF cases mutate)."""

    files: dict[str, bytes]

    @classmethod
    def make(cls, work: Path) -> Seeds:
        from mpc.cli.main import main

        folder = work / "seed"
        arm(folder)
        text = definition("arm.urdf") + ROUTES
        (folder / "model.yml").write_text(text)
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            assert main(["compile", str(folder / "model.yml"), "-o", str(folder / "built")]) == 0
        files = {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
        files["pipeline.yml"] = b"pipeline:\n  root: .\n  model_definitions: [model.yml]\n"
        files["arm.urdf.xacro"] = files["arm.urdf"].replace(
            b'<robot name="arm">', b'<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            b'  <xacro:property name="m" value="2"/>\n  <xacro:include filename="parts.xacro"/>', 1
        ).replace(b'<mass value="2"/>', b'<mass value="${m}"/>', 1)
        files["parts.xacro"] = (b'<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                                b'  <xacro:property name="half" value="${0.5}"/>\n</robot>\n')
        files["xacro.yml"] = definition("arm.urdf.xacro").encode()
        for kind, basefile in (("sdf", "built/sdf/robot.sdf"), ("smurf", "built/smurf/robot.smurf")):
            files[f"{kind}.yml"] = (definition(basefile) + ROUTES).encode()
        shutil.rmtree(folder)
        return cls(files)

    def seed(self, kind: str) -> tuple[str, str]:
        """The file a case of `kind` mutates, and the definition or pipeline file mpc runs."""
        return {"definition": ("model.yml", "model.yml"), "pipeline": ("pipeline.yml", "pipeline.yml"),
                "urdf": ("arm.urdf", "model.yml"), "sdf": ("built/sdf/robot.sdf", "sdf.yml"),
                "smurf": ("built/smurf/robot.smurf", "smurf.yml"),
                "xacro": ("arm.urdf.xacro", "xacro.yml")}[kind]


_COUNTER = itertools.count()


def run_case(seeds: Seeds, base: Path, kind: str, edits: list[Edit], command: str = "compile") -> int:
    """Write the seeds into a fresh folder under `base` with the one file mutated, run mpc
    (`compile`, `check`, or `run` for a pipeline), check the invariants (AssertionError when
    one fails) and return the exit status."""
    from mpc.cli.main import main

    case = Path(os.path.realpath(base)) / f"case{next(_COUNTER)}"
    target, run = seeds.seed(kind)
    for name, data in seeds.files.items():
        path = case / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    original = seeds.files[target].decode()
    (case / target).write_bytes(mutate(original, edits).encode("utf-8", "surrogatepass"))
    (case / "meshes/link.stl").symlink_to("/proc/self/environ")  # for mutations that name it
    before = {p for p in case.rglob("*")}
    args = [command if kind != "pipeline" or command == "check" else "run", str(case / run),
            "-o", str(case / "out")]
    if args[0] == "check":
        args = args[:2]
    err = io.StringIO()
    os.environ["MPC_CACHE_DIR"] = str(case / "cache")
    os.environ["MPC_FUZZ_SECRET"] = SECRET
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            status = main(args)
    finally:
        del os.environ["MPC_FUZZ_SECRET"]
    text = err.getvalue()
    assert SECRET not in text and "root:x:0:0" not in text, f"a secret in the messages: {kind} {edits}"
    assert status in (0, 1), f"exit {status} for {kind} {edits}:\n{text[-3000:]}"
    assert "Traceback" not in text and "internal error" not in text, text[-3000:]
    new = {p for p in case.rglob("*")} - before
    allowed = (case / "out", case / "cache")
    outside = sorted(str(p) for p in new if not any(p == a or a in p.parents for a in allowed))
    assert not outside, f"written outside -o for {kind} {edits}: {outside[:5]}"
    for folder in (base, base.parent, base.parent.parent):
        assert not any(ESCAPE in p.name for p in folder.iterdir()), f"escaped: {kind} {edits}"
    assert not os.path.lexists(ABSOLUTE), f"escaped: {kind} {edits}"
    if (case / "out").is_dir():
        for p in (case / "out").rglob("*"):
            assert not p.is_symlink(), f"a link in the output: {p}"
            if p.is_file():
                data = p.read_bytes()
                assert b"ghp_" not in data and b"PATH=" not in data and SECRET.encode() not in data, p
    shutil.rmtree(case, ignore_errors=True)
    return status

