"""Mutated inputs → one mpc run each, checked: exit 0 or 1, no traceback, nothing written
outside `-o` (and mpc's cache), and every file an accepted run wrote is sound (`Outputs`:
well-formed XML and DAE, finite numbers; URDFs for check_urdf and SDFs for `ign sdf -k`,
collected to be checked in a batch). Shared by the bounded Hypothesis suite (tests/test_fuzz.py)
and the long run (bench/fuzz.py); neither decides how many cases to try, this module does
not either.

A case is a seed input (a definition, a pipeline file, a URDF, an SDF, a SMURF or a xacro
file that mpc reads well) and a list of edits; each edit puts a hostile token (`../`, an
absolute path, a NUL, an alias loop, a 300-character name, an entity, a link to /proc, a
xacro expression that reaches for Python or the environment…) at a place in the text,
deletes, repeats or cuts it. A secret in the environment must reach no message and no output.
The mesh kinds mutate an STL (ASCII), OBJ or DAE file the URDF uses (copied as it is,
converted to STL, OBJ and DAE); `loop` makes a file mpc reads a symbolic link that loops;
`inertia` writes extreme numbers into the inertials of a model exported to MJCF (its
principal axes); `mjcf` mutates the MJCF mpc wrote for the arm, read as the input of a
definition that exports MJCF (actuators, a scene) and USD again. An MJCF an accepted run
wrote must load in MuJoCo, a USD layer in usd-core.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import itertools
import math
import os
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from tests.conftest import definition
from tests.fixtures import arm

KINDS = ("definition", "pipeline", "urdf", "sdf", "smurf", "xacro", "stl", "obj", "dae", "loop", "inertia",
         "mjcf")
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
# The numbers an `inertia` case writes into an inertial: huge, tiny, negative, not finite.
INERTIAS = ("1e308", "-1e308", "1.7e308", "1e200", "1e-320", "-1", "0", "nan", "inf", "-inf", "1e16",
            "5e-324", "3.4e38", "1e154", "-0")


# The exports of the seeds, with the routes from a name to a file name (issue 35.3): a ROS
# package writes each pose as config/init_positions_<pose>.yml, kccd each link's hull as
# meshes/iv/collision_<link>.stl; the poses give a mutation a pose name to hit.
ROUTES = ("      ros_pathes: true\n    - type: sdf\n      mesh_format: stl\n    - type: kccd\n"
          "  ros_pkg_name: robot_model\n  poses:\n    init:\n      shoulder: 0.1\n")
# An MJCF case's exports: MJCF to simulate (actuators, a scene) and USD, each checked by its consumer.
MJCF_EXPORTS = ("    - type: mjcf\n      actuators: position\n      scene: true\n    - type: usd\n"
                "      layout: single\n  poses:\n    init:\n      shoulder: 0.1\n")


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
        # the MJCF input: the arm as mpc writes it for MuJoCo, with a keyframe, an actuator and a scene
        (folder / "mjcf_seed.yml").write_text(definition("arm.urdf") + MJCF_EXPORTS)
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            assert main(["compile", str(folder / "model.yml"), "-o", str(folder / "built")]) == 0
            assert main(["compile", str(folder / "mjcf_seed.yml"), "-o", str(folder / "built_mjcf")]) == 0
        files = {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
        files["pipeline.yml"] = b"pipeline:\n  root: .\n  model_definitions: [model.yml]\n"
        files["arm.urdf.xacro"] = files["arm.urdf"].replace(
            b'<robot name="arm">', b'<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            b'  <xacro:property name="m" value="2"/>\n  <xacro:include filename="parts.xacro"/>', 1
        ).replace(b'<mass value="2"/>', b'<mass value="${m}"/>', 1)
        files["parts.xacro"] = (b'<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                                b'  <xacro:property name="half" value="${0.5}"/>\n</robot>\n')
        files["xacro.yml"] = definition("arm.urdf.xacro").encode()
        files.update(_mesh_seeds())
        files["inertia.yml"] = (definition("arm.urdf") + "    - type: mjcf\n").encode()
        for kind, basefile in (("sdf", "built/sdf/robot.sdf"), ("smurf", "built/smurf/robot.smurf")):
            files[f"{kind}.yml"] = (definition(basefile) + ROUTES).encode()
        files["mjcf.yml"] = (definition("built_mjcf/mjcf/robot.xml") + MJCF_EXPORTS).encode()
        shutil.rmtree(folder)
        return cls(files)

    def seed(self, kind: str) -> tuple[str, str]:
        """The file a case of `kind` mutates, and the definition or pipeline file mpc runs."""
        return {"definition": ("model.yml", "model.yml"), "pipeline": ("pipeline.yml", "pipeline.yml"),
                "urdf": ("arm.urdf", "model.yml"), "sdf": ("built/sdf/robot.sdf", "sdf.yml"),
                "smurf": ("built/smurf/robot.smurf", "smurf.yml"),
                "xacro": ("arm.urdf.xacro", "xacro.yml"), "stl": ("meshes/m.stl", "meshes.yml"),
                "obj": ("meshes/m.obj", "meshes.yml"), "dae": ("meshes/m.dae", "meshes.yml"),
                "loop": ("model.yml", "pipeline.yml"), "inertia": ("arm.urdf", "inertia.yml"),
                "mjcf": ("built_mjcf/mjcf/robot.xml", "mjcf.yml")}[kind]


def _mesh_seeds() -> dict[str, bytes]:
    """A box as ASCII STL, OBJ and DAE, a URDF whose links use them, and a definition that
    copies them (URDF, input_type) and converts them (SDF to DAE, MJCF to OBJ)."""
    import trimesh

    from mpc.core.collada import stable

    box = trimesh.creation.box(extents=(0.1, 0.2, 0.3))
    links = "".join(f'''
  <link name="{fmt}">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><geometry><mesh filename="meshes/m.{fmt}"/></geometry></visual>
    <collision><geometry><mesh filename="meshes/m.{fmt}"/></geometry></collision></link>'''
                    for fmt in ("stl", "obj", "dae"))
    joints = "".join(f'''
  <joint name="{a}_{b}" type="revolute"><parent link="{a}"/><child link="{b}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'''
                     for a, b in (("stl", "obj"), ("obj", "dae")))
    urdf = f'<?xml version="1.0"?>\n<robot name="meshes">{links}{joints}\n</robot>\n'
    exports = ("    - type: sdf\n      mesh_format: dae\n    - type: mjcf\n      mesh_format: obj\n")
    return {"meshes/m.stl": box.export(file_type="stl_ascii").encode(),
            "meshes/m.obj": box.export(file_type="obj").encode(),
            "meshes/m.dae": stable(box.export(file_type="dae")), "meshes.urdf": urdf.encode(),
            "meshes.yml": (definition("meshes.urdf") + exports).encode()}


_COUNTER = itertools.count()


_INERTIAL_VALUE = re.compile(r'\b(?:ixx|ixy|ixz|iyy|iyz|izz|value)="([^"]*)"')
LOOPED = ("arm.urdf", "meshes/tetra.stl", "model.yml", "meshes", "pipeline.yml")  # what `loop` cases loop


def mutate_inertia(text: str, edits: list[Edit]) -> str:
    """Each edit writes one of INERTIAS into the mass or an inertia entry it points at."""
    for e in edits:
        spans = [m.span(1) for m in _INERTIAL_VALUE.finditer(text)]
        start, end = spans[min(int(e.where * len(spans)), len(spans) - 1)]
        text = text[:start] + INERTIAS[e.token % len(INERTIAS)] + text[end:]
    return text


def make_loop(case: Path, edits: list[Edit]) -> None:
    """Make a file mpc reads a symbolic link that loops: to itself, or through a second link."""
    for e in edits[:2]:
        path = case / LOOPED[e.token % len(LOOPED)]
        if not path.parent.is_dir():  # inside a folder the first edit looped
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)
        if e.where < 0.5:
            path.symlink_to(path.name)
        else:
            other = path.with_name(path.name + ".other")
            other.unlink(missing_ok=True)
            other.symlink_to(path.name)
            path.symlink_to(other.name)


@dataclass
class Outputs:
    """What accepted runs wrote, checked: `check` at once (well-formed XML and DAE, finite
    numbers in XML and YAML), URDFs and a sample of SDFs kept under `folder` for
    `consumers_refuse` (check_urdf, `ign sdf -k`: a process each, run in a batch)."""

    folder: Path
    sdf_every: int = 20  # `ign sdf -k` takes a second: one SDF in this many
    invalid: list[str] = field(default_factory=list)
    urdfs: list[tuple[Path, str]] = field(default_factory=list)
    sdfs: list[tuple[Path, str]] = field(default_factory=list)
    files: int = 0
    _sdf_seen: int = 0

    def check(self, out: Path, label: str, inputs: frozenset[str] = frozenset()) -> None:
        """inputs: the SHA-256 of each file the case gave mpc; a DAE of the same bytes is the
        user's mesh copied as it is, judged as mpc's reader judged it (`copy_problem`)."""
        for path in sorted(out.rglob("*")):
            if not path.is_file() or path.suffix not in (".urdf", ".sdf", ".xml", ".dae", ".config", ".smurf",
                                                         ".yml", ".usda", ".usdc"):
                continue
            self.files += 1
            if path.suffix == ".dae" and hashlib.sha256(path.read_bytes()).hexdigest() in inputs:
                problem = copy_problem(path)
            else:
                problem = output_problem(path) if path.suffix not in (".usda", ".usdc") else None
            if problem is None and path.parent.name in ("mjcf", "usd") and path.suffix != ".dae":
                problem = consumer_refuses(path)
            if problem is not None:
                self.invalid.append(f"{label}: {path.relative_to(out)}: {problem}")
                continue
            if path.suffix == ".urdf":
                self.urdfs.append((self._keep(path), f"{label}: {path.relative_to(out)}"))
            elif path.suffix == ".sdf":
                self._sdf_seen += 1
                if self._sdf_seen % self.sdf_every == 1 or self.sdf_every == 1:
                    kept = self._keep(path, with_meshes=out)
                    self.sdfs.append((kept, f"{label}: {path.relative_to(out)}"))

    def _keep(self, path: Path, with_meshes: Path | None = None) -> Path:
        folder = self.folder / f"o{len(self.urdfs) + len(self.sdfs)}"
        if with_meshes is not None:  # the SDF with the meshes it names, where it names them
            shutil.copytree(with_meshes, folder, symlinks=True)
            return folder / path.relative_to(with_meshes)
        folder.mkdir(parents=True)
        return Path(shutil.copy(path, folder))

    def consumers_refuse(self) -> list[str]:
        """check_urdf on every URDF kept and `ign sdf -k` on every SDF kept: what they refuse."""
        refused = []
        for path, label in self.urdfs:
            run = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True)
            said = run.stdout + run.stderr
            if run.returncode != 0 or "Error" in said or "ERROR" in said:
                refused.append(f"{label}: check_urdf: {said.strip()[-500:]}")
        for path, label in self.sdfs:
            run = subprocess.run([shutil.which("ign") or "ign", "sdf", "-k", str(path)], capture_output=True,
                                 text=True, cwd=path.parent)
            if run.returncode != 0 or "Error" in run.stdout + run.stderr:
                refused.append(f"{label}: ign sdf -k: {(run.stdout + run.stderr).strip()[-500:]}")
        self.urdfs.clear()
        self.sdfs.clear()
        shutil.rmtree(self.folder, ignore_errors=True)
        self.folder.mkdir(parents=True, exist_ok=True)
        return refused


MUJOCO_WARNINGS: list[str] = []  # what MuJoCo said of the MJCF files it loaded (consumer_refuses)


def consumer_refuses(path: Path) -> str | None:
    """Why MuJoCo refuses an MJCF file mpc wrote (the robot's, or the scene that includes it),
    or usd-core a USD layer (the stage it opens, with every payload and sublayer); None when
    it loads."""
    if path.suffix == ".xml":
        import mujoco

        # MuJoCo's warnings (a joint-space inertia it finds near singular) are counted, not left
        # to MuJoCo, which prints them and appends them to MUJOCO_LOG.TXT in the working folder.
        before = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda message: MUJOCO_WARNINGS.append(f"{path.name}: {message}"))
        try:
            mujoco.MjModel.from_xml_path(str(path))
        except Exception as e:
            return f"MuJoCo refuses it: {e}"
        finally:
            mujoco.set_mju_user_warning(before)
        return None
    from pxr import Tf, Usd

    try:
        stage = Usd.Stage.Open(str(path))
    except Tf.ErrorException as e:
        return f"usd-core cannot open it: {e}"
    if stage is None:
        return "usd-core cannot open it"
    for prim in stage.Traverse():
        for attribute in prim.GetAttributes():  # as written (a schema's fallback may be inf)
            value = attribute.Get() if attribute.HasAuthoredValue() else None
            if isinstance(value, float) and not math.isfinite(value):
                return f"a number that is not finite: {attribute.GetPath()}"
    return None


def copy_problem(path: Path) -> str | None:
    """Why a mesh mpc copied as it is (a DAE) is unsound, or None: XML that libxml2, mpc's
    reader, does not find well-formed. expat (`output_problem`) keeps XML 1.0's names before
    its fifth edition: a user's DAE may hold a name that only the fifth edition allows (a
    U+FEFF in an attribute's name), which libxml2 and tinyxml2 (Gazebo's) read."""
    from lxml import etree

    from mpc.core.span import hardened_parser

    try:
        etree.parse(str(path), hardened_parser(huge=True))
    except etree.XMLSyntaxError as e:
        return f"not well-formed XML: {e}"
    return None


def output_problem(path: Path) -> str | None:
    """Why a file mpc wrote is unsound, or None: XML (URDF, SDF, MJCF, DAE) that is not
    well-formed for a namespace-aware parser (expat), a number in it that is not finite; YAML
    (SMURF) that does not load, or holds a number that is not finite (but a `.nan` bound of a
    joint_limits file, where ROCK reads it as "no limit": a continuous joint's position)."""
    data = path.read_bytes()
    if path.suffix in (".smurf", ".yml"):
        import yaml

        try:
            doc = yaml.safe_load(data)
        except yaml.YAMLError as e:
            return f"not YAML: {e}"
        stack = [doc]
        while stack:
            x = stack.pop()
            if isinstance(x, float) and not math.isfinite(x) and not (
                    math.isnan(x) and path.name.startswith("joint_limits")):
                return f"a number that is not finite: {x}"
            stack.extend(x.values() if isinstance(x, dict) else x if isinstance(x, list) else ())
        return None
    numbers: list[str] = []
    parser = expat.ParserCreate(namespace_separator=" ")
    parser.StartElementHandler = lambda _tag, attrs: numbers.extend(
        v for k, v in attrs.items() if k not in _NAMES)
    parser.CharacterDataHandler = numbers.append
    try:
        parser.Parse(data, True)
    except expat.ExpatError as e:
        return f"not well-formed XML: {e}"
    if path.name == "package.xml":  # a ROS package's names and words (`nan` names a package well)
        return None
    for text in numbers:
        words = text.split()
        if words and all(map(_NUMBER.fullmatch, words)) and not all(math.isfinite(float(w)) for w in words):
            return f"a number that is not finite: '{text.strip()[:80]}'"
    return None


_NAMES = frozenset(("name", "link", "joint", "parent", "child", "filename", "type", "body", "mesh", "class",
                    "material", "texture", "file", "uri", "id", "url", "sid", "source", "target", "symbol",
                    "profile", "semantic", "version", "meta", "axis_name"))
_NUMBER = re.compile(r"[-+]?(\d+\.?\d*(e[-+]?\d+)?|\.\d+(e[-+]?\d+)?|nan|inf|infinity)", re.IGNORECASE)


def run_case(seeds: Seeds, base: Path, kind: str, edits: list[Edit], command: str = "compile",
             outputs: Outputs | None = None) -> int:
    """Write the seeds into a fresh folder under `base` with the one file mutated, run mpc
    (`compile`, `check`, or `run` for a pipeline), check the invariants (AssertionError when
    one fails), hand what an accepted run wrote to `outputs` and return the exit status."""
    from mpc.cli.main import main

    case = Path(os.path.realpath(base)) / f"case{next(_COUNTER)}"
    target, run = seeds.seed(kind)
    for name, data in seeds.files.items():
        path = case / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    original = seeds.files[target].decode()
    if kind == "loop":
        make_loop(case, edits)
        run = "pipeline.yml" if command in ("check", "run") else "model.yml"
    elif kind == "inertia":
        (case / target).write_text(mutate_inertia(original, edits))
    else:
        (case / target).write_bytes(mutate(original, edits).encode("utf-8", "surrogatepass"))
    if (case / "meshes").is_dir() and not (case / "meshes").is_symlink():
        (case / "meshes/link.stl").symlink_to("/proc/self/environ")  # for mutations that name it
    before = {p for p in case.rglob("*")}
    inputs = frozenset(hashlib.sha256(p.read_bytes()).hexdigest() for p in before
                       if p.is_file() and not p.is_symlink())
    pipeline = kind == "pipeline" or (kind == "loop" and run == "pipeline.yml")
    args = [command if not pipeline or command == "check" else "run", str(case / run),
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
        if status == 0 and outputs is not None:
            outputs.check(case / "out", f"{kind} {command} {edits}", inputs)
    shutil.rmtree(case, ignore_errors=True)
    return status

