"""A definition's last build, kept → the next `mpc compile` of it on the same inputs writes the
kept outputs, or starts at writing them.

A build is a function of what it reads. What the front end and the ops compute (compiler/
front_end.py: load, merge defaults, validate, lower, run the passes, read the inputs, apply
the ops) depends only on:
- mpc (its version with the digest of its sources, core/version.py), the Python running it
  and the distributions installed beside it (xacro, lxml, trimesh shape results);
- the definition's path as given, the working folder, `--package` and the environment, less
  the variables a shell sets by itself (`_SESSION`);
- the files it opened (core/reads.py records them): the definition, its defaults, the
  derived_base definitions, the input models and what xacro includes, each by its bytes,
  and those it looked for and did not find;
- the folder each `package://` name resolved to;
- the files the program and the robot name but did not open (meshes, compare models):
  which file each path leads to and what it is, since the readers refuse a link out of the
  package roots or a special file, and must refuse a file swapped for one.
The outputs depend, besides, on the files that writing them opened (the mesh files, by
their bytes) and on the programs they were made with (`pdf`: Graphviz, `render`: EGL and
Mesa, `kccd`'s tools: core/programs.py notes their files); `post_processing` commands, whose
reads no one sees, make outputs that are not kept.

A kept build is used only when all of this is as it was, and its diagnostics are reported
again. Not kept: a build that failed (it runs again and says why again), one that fetched a
branch of a repository (what it holds changes on the remote), one whose files changed
while it ran, and the builds of `mpc run` (whose fingerprints skip whole models) and of
`mpc lsp` (which keeps its input models itself).

One entry per definition (its path as given and the working folder), replaced by its next
build, in `$MPC_CACHE_DIR/builds/`: a verified entry (core/cache.py) of two lines of JSON,
the dependencies, outputs and diagnostics, then the program and the robot (compiler/
kept_values.py: data that no reading of it can make run). Beside it, a copy of the outputs
(never the delivered files themselves: a clone or a copy), but for those that are copies of
a mesh entry of the cache or of a file the build read (a mesh copied as it is), which it
names: making a hundred files cost a cold build more than its meshes' bytes. Each file is
checked against its SHA-256 when it is written out again. Anyone who can write the cache can
change what a build delivers, but not make mpc run anything: an entry that is not of this
form (a pickle of an earlier mpc, a crafted one) is refused unread with a warning (W0650),
and the build runs.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import stat
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any, cast

from mpc.compiler.kept_values import BadValue, dumps, loads
from mpc.core import cache
from mpc.core.blas import user_environment
from mpc.core.diagnostics import Diagnostic, Sink
from mpc.core.files import copy_file, name_problem
from mpc.core.packages import interpreter_sites
from mpc.core.reads import ReadRecorder, recording
from mpc.core.span import Span

if TYPE_CHECKING:  # the program and robot are kept as values, their modules imported when read
    from mpc.compiler.options import Options
    from mpc.ir.program import Program
    from mpc.ir.robot import Robot

# Variables that a shell or a terminal sets by itself, or that change how mpc runs but not what
# it builds.
_SESSION = frozenset({
    "_", "OLDPWD", "PWD", "SHLVL", "TERM", "COLORTERM", "COLUMNS", "LINES", "PS1", "PS2", "PS4",
    "PROMPT_COMMAND", "HISTFILE", "HISTSIZE", "HISTFILESIZE", "HISTCONTROL", "LS_COLORS", "LESS",
    "LESSOPEN", "LESSCLOSE", "MAIL", "DISPLAY", "WINDOWID", "STY", "TMUX", "TMUX_PANE",
    "DBUS_SESSION_BUS_ADDRESS", "VTE_VERSION", "TERM_PROGRAM", "TERM_PROGRAM_VERSION",
    "TERM_SESSION_ID", "SSH_CLIENT", "SSH_CONNECTION", "SSH_TTY", "SSH_AUTH_SOCK", "SSH_AGENT_PID",
    "GPG_AGENT_INFO", "XDG_SESSION_ID", "XDG_SESSION_TYPE", "XDG_SESSION_CLASS", "XDG_VTNR",
    "XDG_SEAT", "MPC_PROFILE", "MPC_CACHE_TRACE", "MPC_MESH_WORKERS", "PYTHONDONTWRITEBYTECODE",
    "PYTHONUNBUFFERED", "PYTHONFAULTHANDLER", "PYTHONPROFILEIMPORTTIME", "PYTHONBREAKPOINT",
})
# What a build says about the state of mpc's own cache (W0650: a damaged mesh entry, computed
# again), which the next build of the same inputs does not find: not said again.
_OF_THE_CACHE = frozenset({"W0650"})
# A file changed this close to the start of the build (or later) may have changed after the
# build read it, within one tick of the file system's clock: the build is not kept. File
# systems with whole-second times (FAT, some network ones) get two seconds.
_FINE_NS, _COARSE_NS = 20_000_000, 2_000_000_000

Files = list[tuple[str, str | None]]  # (path, SHA-256 of its bytes, or None: looked for, missing)


def kept_folder(path: Path) -> Path:
    """Where the build of the definition at `path`, compiled from this working folder, is kept."""
    where = json.dumps([str(path), os.getcwd()])
    return cache.cache_dir("builds") / hashlib.sha256(where.encode()).hexdigest()


class KeptBuild:
    """One compilation's use of the build cache: the build kept for its definition (when all it
    depends on is as it was), and the recording of what this compilation reads."""

    def __init__(self, folder: Path, key: str, options: Options) -> None:
        self.folder, self.key, self.options = folder, key, options
        self.entry = folder / "entry"
        self.header: dict[str, Any] | None = None  # the kept build, its model's dependencies hold
        self.outputs_hold = False  # … and those of its outputs (never for --force)
        self.model_used = False  # this build took the kept program and robot
        self.program_used = False  # … the kept program alone (--force)
        self.refused: str | None = None  # why the entry found was not read (W0650), if it was not
        # the kept program and robot as the entry holds them, and read:
        self._program_json, self._robot_json = b"", b""
        self._entry_data = b""  # the entry as read: one kept again unchanged is not rewritten
        self.meshes = cache.cache_dir("meshes")  # where the outputs' mesh entries are (`copies`)
        self._program: Program | None = None
        self._model: tuple[Program, Robot] | None = None
        self.recorder = ReadRecorder(ignore=[cache.cache_dir("")])  # derived data, commits' checkouts
        self.front_reads: int | None = None  # how many of the files recorded the model's reads
        self.front_said = 0  # how many of the model's diagnostics the front end said
        self._sink: Sink | None = None  # where this build reports, from `recording`
        self._said_before = 0
        self.started = time.time_ns()
        # `encode_model`'s program and robot, their JSON and the paths it names
        self._encoded: tuple[Program, Robot, tuple[bytes, bytes] | None, list[PurePath]] | None = None

    @classmethod
    def open(cls, path: Path, options: Options) -> KeptBuild | None:
        """The cache of the definition at `path`, or None for builds that are not kept (pipeline
        defaults, a server's kept models)."""
        if options.defaults is not None or options.models is not None:
            return None
        from mpc.core.version import source_version

        where = [str(path), os.getcwd()]
        resolver = options.resolver
        key = json.dumps([
            where, source_version(), sys.version, sys.prefix, _distributions(),
            sorted((k, str(v)) for k, v in resolver.package_map.items()),
            [str(p) for p in resolver.search_path or ()], [str(p) for p in resolver.roots],
            [str(p) for p in resolver.projects],
            sorted((k, v) for k, v in user_environment().items() if k not in _SESSION),
            *([] if options.post_processing else ["no post_processing"]),
        ])
        kept = cls(kept_folder(path), hashlib.sha256(key.encode()).hexdigest(), options)
        kept._load()
        return kept

    def report_refused(self, sink: Sink, span: Span) -> None:
        """Say (W0650, at `span`: the definition) that the entry found was refused, if it was."""
        if self.refused is not None:
            sink.warning(span, "W0650", f"the kept build '{self.entry}' is unusable ({self.refused}); "
                         "it is removed and the model is built again")
            self.refused = None

    # -- what is kept ----------------------------------------------------------------------------

    @property
    def modelname(self) -> str:
        assert self.header is not None
        return self.header["modelname"]  # type: ignore[no-any-return]

    @property
    def span(self) -> Span:
        assert self.header is not None
        return self.header["span"]  # type: ignore[no-any-return]

    @property
    def force(self) -> bool:
        """`--force`: the kept program may be used, the robot and the outputs are built anew."""
        return self.options.force

    def program(self) -> Program:
        """The kept program, read when first asked for; raises BadValue when the entry does not
        hold one."""
        assert self.header is not None
        if self._program is None:
            from mpc.ir.program import Program

            program = loads(self._program_json)
            _check(isinstance(program, Program), "program")
            self._program = program
            return program
        return self._program

    def model(self) -> tuple[Program, Robot]:
        """The kept program and robot, read when first asked for (a build that writes its kept
        outputs seldom needs them); raises BadValue when the entry does not hold them."""
        if self._model is None:
            program = self.program()
            from mpc.ir.robot import Robot

            robot = loads(self._robot_json)
            _check(isinstance(robot, Robot), "robot")
            self._model = program, robot
        return self._model

    def model_holds(self, sink: Sink, span: Span) -> bool:
        """Whether what this build may take from the entry can be read (the program and robot,
        the program alone for --force); when not, the entry is refused (W0650 into `sink`, at
        `span`) and forgotten: the front end runs."""
        try:
            self.program() if self.force else self.model()
        except BadValue as e:
            self._refuse(f"it is not a kept build: {e}")
            self.header, self.outputs_hold = None, False
            self.report_refused(sink, span)
            return False
        return True

    def replay_model(self, sink: Sink) -> tuple[Program, Robot] | tuple[None, None]:
        """The kept program and robot (`model_holds` said they can be read), their diagnostics
        reported into `sink` again; (None, None) when `sink` makes one of them an error (--werror)."""
        assert self.header is not None and not self.force
        self.model_used = True
        _report(sink, self.header["diagnostics"])
        return (None, None) if sink.has_errors() else self.model()

    def replay_program(self, sink: Sink) -> Program | None:
        """The kept program (--force; `model_holds` said it can be read), the front end's
        diagnostics reported into `sink` again; None when `sink` makes one an error (--werror)."""
        assert self.header is not None and self.force
        self.program_used = True
        _report(sink, self.header["diagnostics"][:self.header["front"]])
        return None if sink.has_errors() else self.program()

    def write_outputs(self, staging: Path) -> bool:
        """Copy the kept outputs into `staging`; False (nothing reported) when one is not the
        file that was kept, or not a regular file inside the kept folder. Raises OSError when
        `staging` cannot be written."""
        assert self.header is not None and self.outputs_hold
        outputs = self.header["outputs"]
        kept = self.folder / outputs["folder"]
        for folder in outputs["folders"]:
            (staging / folder).mkdir(parents=True, exist_ok=True)
        if kept.is_symlink():
            return False  # a link put into the cache: never read through
        inside = os.path.realpath(kept) + os.sep
        copies = {name: Path(origin) for name, origin in outputs["copies"]}
        inputs = {f for f, _ in outputs["read"]} | {f for f, _ in self.header["files"]}
        for name, digest in outputs["files"]:
            source = copies.get(name)
            try:
                if source is None:
                    source = kept / name
                    if not os.path.realpath(source).startswith(inside):
                        return False  # a link put into the cache: never read through
                    link = os.O_NOFOLLOW
                elif source.parent == self.meshes:  # a mesh entry, never read through a link
                    cache.touch_entry(source)  # used: `mpc ci job` passes it on
                    link = os.O_NOFOLLOW
                elif str(source) in inputs:  # a file the build read, as it was then (its digest)
                    link = 0
                else:
                    return False
                # without waiting on a FIFO put in a file's place
                fd = os.open(source, os.O_RDONLY | link | os.O_NONBLOCK | os.O_CLOEXEC)
                with open(fd, "rb") as f:
                    if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                        return False
                    data = f.read()
                    if cache.digest_of_read(f, source, data) != digest:  # a settled file: by its status
                        return False
            except OSError:
                return False
            (staging / name).write_bytes(data)
        return True

    def replay_outputs(self, sink: Sink) -> None:
        """The diagnostics of the kept build, reported into `sink` again."""
        assert self.header is not None
        _report(sink, self.header["diagnostics"])
        _report(sink, self.header["outputs"]["diagnostics"])

    def drop_outputs(self) -> None:
        """The kept outputs are damaged: not written out, nor kept again by this build."""
        self.outputs_hold = False
        if self.header is not None:
            self.header["outputs"] = None
        with contextlib.suppress(OSError):
            cache.remove_entry(self.entry)

    # -- keeping ---------------------------------------------------------------------------------

    @contextlib.contextmanager
    def recording(self, sink: Sink) -> Iterator[None]:
        """Record what the build reads, and (`program_done`) what its front end says into `sink`."""
        self._sink, self._said_before = sink, len(sink.diagnostics)
        with recording(self.recorder):
            yield

    def program_done(self) -> None:
        """The front end has made the program: what it said so far is the front end's."""
        assert self._sink is not None
        self.front_said = len(self._sink.diagnostics) - self._said_before

    def front_end_done(self) -> None:
        """What was opened so far is what the program and the robot depend on."""
        self.front_reads = len(self.recorder.read)

    def keep(self, program: Program, robot: Robot, model_diagnostics: list[Diagnostic],
             out: Path | None, output_diagnostics: list[Diagnostic]) -> None:
        """Keep this build: its program and robot, and (`out`: the folder it wrote, when every
        export is one whose files can be kept) its outputs."""
        if self.recorder.volatile or (self.front_reads is None and not self.model_used):
            return
        header: dict[str, Any]
        if self.header is not None and self.model_used:
            header = {**self.header, "outputs": None}
            model_json = self._program_json, self._robot_json
        else:
            model_files = _digests(self.recorder.inputs(first=self.front_reads), self.started)
            if model_files is None:
                return
            packages = {(p, n): f for (p, n), f in self.recorder.packages.items()}
            opened = {f for f, _ in model_files}
            if self.header is not None and self.program_used:
                # --force from the kept program: its dependencies, read by the build that made
                # it, still hold, and the ops ran anew on them, unchanged: they made the robot
                # the entry holds, whose JSON is kept again as it was.
                model_files = list({**dict(self.header["files"]), **dict(model_files)}.items())
                packages = {(p, n): f for p, n, f in self.header["packages"]} | packages
                model_json, named = (self._program_json, self._robot_json), self.header["named"]
            else:
                encoded, paths = self.encode_model(program, robot)
                if encoded is None:
                    return  # a value that cannot be kept: the next build runs in full
                model_json = encoded
                named = [(p, *_where(p)) for p in sorted(set(map(str, paths)) - opened)]
            try:
                diagnostics = _kept_diagnostics(model_diagnostics)
            except (TypeError, ValueError, RecursionError):
                return
            front = len(_kept_diagnostics(model_diagnostics[:self.front_said]))
            header = {"key": self.key, "files": model_files, "named": named,
                      "packages": sorted((p, n, f) for (p, n), f in packages.items()),
                      "diagnostics": diagnostics, "front": front, "modelname": program.modelname,
                      "span": program.span, "outputs": None}
        from mpc.backends.formats import FORMATS

        with contextlib.suppress(OSError):
            # Kept: the exports whose files depend only on the program, the robot and the files
            # mpc reads (`kept` in the formats' table).
            if out is not None and all(FORMATS[e.type].kept for e in program.exports):
                opened = {f for f, _ in header["files"]}
                header["outputs"] = self._keep_outputs(out, output_diagnostics, opened)
            try:
                data = _entry_bytes(header, model_json)
            except (TypeError, ValueError, RecursionError):
                return
            if data == self._entry_data:
                cache.touch_entry(self.entry)  # the same entry: used, not written again
            else:
                self.folder.mkdir(parents=True, exist_ok=True)
                cache.store_entry(self.entry, data)
            cache.trace(f"keep build {self.folder.name}")
            self._remove_old_outputs(header["outputs"])

    def encode_model(self, program: Program, robot: Robot
                     ) -> tuple[tuple[bytes, bytes] | None, list[PurePath]]:
        """The JSON `keep` writes of the program and the robot (None when a value in them cannot
        be kept), and the paths they name; made once for them, which a build does while its mesh
        worker starts on the meshes (core/meanwhile.py)."""
        if self._encoded is None or self._encoded[0] is not program or self._encoded[1] is not robot:
            paths = list[PurePath]()
            try:
                encoded: tuple[bytes, bytes] | None = dumps(program, paths), dumps(robot, paths)
            except (TypeError, ValueError, RecursionError):
                encoded = None
            self._encoded = program, robot, encoded, paths
        return self._encoded[2], self._encoded[3]

    def _keep_outputs(self, out: Path, diagnostics: list[Diagnostic],
                      model_files: set[str]) -> dict[str, Any] | None:
        """A copy of the outputs in `out`: clones where the file system makes them (they share
        no storage: a write into one leaves the other as it was), else copies. The copy kept
        before is kept again when it holds the same files, each with its digest (a rebuild
        with --force of what did not change need not write the outputs twice more)."""
        files = _digests([p for p in self.recorder.inputs() if str(p) not in model_files], self.started)
        if files is None:
            return None
        names: list[tuple[str, str]] = []
        copies: list[tuple[str, str]] = []
        folders: list[str] = []
        inputs = {f for f, _ in files} | model_files  # what `write_outputs` may read besides
        for here, dirs, found in os.walk(out):
            rel = Path(here).relative_to(out)
            folders += (str(rel / name) for name in dirs)
            for name in found:
                source = Path(here) / name
                try:
                    st = os.lstat(source)  # a regular file, no link: its lstat is its stat
                except OSError:
                    return None
                if not stat.S_ISREG(st.st_mode):
                    return None
                noted = cache.written_copy(st)  # a mesh out of the cache, unchanged since
                if noted is None:
                    with open(source, "rb") as f:
                        noted = hashlib.file_digest(f, "sha256").hexdigest(), None
                digest, origin = noted
                names.append((str(rel / name), digest))
                if origin is not None and (origin.parent == self.meshes or str(origin) in inputs):
                    copies.append((str(rel / name), str(origin)))
        kept = {"files": sorted(names), "folders": sorted(folders), "copies": sorted(copies),
                "read": files, "diagnostics": _kept_diagnostics(diagnostics)}
        before = self.header["outputs"] if self.header is not None else None
        if (before is not None and [list(f) for f in kept["files"]] == before["files"]
                and [list(f) for f in kept["copies"]] == before["copies"]
                and kept["folders"] == before["folders"] and self._intact(before, out)):
            return {**kept, "folder": before["folder"]}
        self.folder.mkdir(parents=True, exist_ok=True)
        copy = Path(tempfile.mkdtemp(prefix="outputs-", dir=self.folder))
        for folder in kept["folders"]:
            (copy / folder).mkdir()
        copied = dict(copies)
        for name, _ in kept["files"]:
            if name not in copied:
                copy_file(out / name, copy / name)  # a file changed since is found when written out
        return {**kept, "folder": copy.name}

    def _intact(self, outputs: dict[str, Any], out: Path) -> bool:
        """Whether the kept copy of `outputs` (the same files as in `out`, by their digests) is
        still there: each file a regular file of the cache (or the file it names), of the size of
        its twin in `out`. Its bytes are checked against their digests when they are written out
        (`write_outputs`); a damaged copy is then dropped (`drop_outputs`), and the build that
        runs instead keeps a new one."""
        folder = self.folder / outputs["folder"]
        if folder.is_symlink() or not folder.is_dir():
            return False
        copies = dict(outputs["copies"])
        for name, _ in outputs["files"]:
            try:
                st = os.stat(copies[name]) if name in copies else os.lstat(folder / name)
                if not stat.S_ISREG(st.st_mode) or st.st_size != os.stat(out / name).st_size:
                    return False
            except OSError:
                return False
        return True

    def _remove_old_outputs(self, kept: dict[str, Any] | None) -> None:
        for folder in self.folder.glob("outputs-*"):
            if kept is None or folder.name != kept["folder"]:
                shutil.rmtree(folder, ignore_errors=True)

    # -- checking what is kept -------------------------------------------------------------------

    def _load(self) -> None:
        data, why = cache.load_entry(self.entry)
        if data is None:
            if why is not None:
                self._refuse(why)
            return
        try:
            header, self._program_json, self._robot_json = _read_entry(data)
            self._entry_data = data
        except BadValue as e:
            self._refuse(f"it is not a kept build: {e}")
            return
        if header["key"] != self.key or not _files_hold(header["files"]) or not self._names_hold(header):
            return
        self.header = header
        outputs = header["outputs"]
        self.outputs_hold = not self.force and outputs is not None and _files_hold(outputs["read"])
        cache.trace(f"reuse build {self.folder.name}" + (" with its outputs" if self.outputs_hold else
                                                         " for its program" if self.force else ""))

    def _refuse(self, why: str) -> None:
        """The entry must not be used: say why (`report_refused`) and remove it."""
        self.refused = why
        cache.trace(f"refuse build {self.folder.name}")
        with contextlib.suppress(OSError):
            cache.remove_entry(self.entry)

    def _names_hold(self, header: dict[str, Any]) -> bool:
        if any(_where(p) != (dev, ino, kind) for p, dev, ino, kind in header["named"]):
            return False
        for package, near, found in header["packages"]:
            folder = self.options.resolver.find(package, Path(near) if near else None)
            if (str(folder) if folder is not None else None) != found:
                return False
        return True


# -- the entry's form ----------------------------------------------------------------------------
# Four lines of JSON (JSON escapes every newline in a string): the header, as JSON's own
# values; the span and the diagnostics of the header, the program, and the robot, each written
# by compiler/kept_values.py. The program and the robot are read when first asked for. `front`
# counts the diagnostics (the first ones) that the front end said.
_FORM = "mpc kept build 4"
_HEADER_KEYS = frozenset({"form", "key", "files", "named", "packages", "front", "modelname", "outputs"})
_OUTPUT_KEYS = frozenset({"folder", "files", "folders", "copies", "read"})
_VALUES = ("span", "diagnostics")  # of the header, on the second line


def _entry_bytes(header: dict[str, Any], model_json: tuple[bytes, bytes]) -> bytes:
    out = header["outputs"]
    plain = {**{k: header[k] for k in _HEADER_KEYS - {"form"}}, "form": _FORM,
             "outputs": None if out is None else {k: out[k] for k in _OUTPUT_KEYS}}
    values = [*(header[k] for k in _VALUES), None if out is None else out["diagnostics"]]
    return b"\n".join([json.dumps(plain, separators=(",", ":")).encode(), dumps(values), *model_json])


def _read_entry(data: bytes) -> tuple[dict[str, Any], bytes, bytes]:
    """The header (its values read), the program's JSON and the robot's of an entry; raises
    BadValue when it is not an entry of this form, each part of the shape `keep` writes."""
    first, _, rest = data.partition(b"\n")
    second, newline, model_json = rest.partition(b"\n")
    program_json, newline_, robot_json = model_json.partition(b"\n")
    try:
        header = json.loads(first)
    except (ValueError, RecursionError):  # a pickle of an earlier mpc, say: never unpickled
        raise BadValue("not JSON") from None
    if (type(header) is not dict or header.get("form") != _FORM or header.keys() != _HEADER_KEYS
            or not newline or not newline_):
        raise BadValue("not the header of a kept build")
    _check(type(header["key"]) is str and type(header["modelname"]) is str, "key, model name")
    _check_files(header["files"])
    _check(_rows(header["named"], (str, int, int, str)), "named files")
    _check(_rows(header["packages"], (str, str, (str, type(None)))), "packages")
    out = header["outputs"]
    if out is not None:
        _check(type(out) is dict and out.keys() == _OUTPUT_KEYS, "outputs")
        _check(type(out["folder"]) is str and out["folder"].startswith("outputs-")
               and name_problem(out["folder"]) is None, "outputs' folder")
        _check(_rows(out["files"], (str, str)) and all(name_problem(n, folders=True) is None
                                                         for n, _ in out["files"]), "output files")
        copies, files = cast("tuple[Any, Any]", (out["copies"], out["files"]))
        _check(_rows(copies, (str, str)) and {n for n, _ in copies} <= {n for n, _ in files}, "output copies")
        _check(type(out["folders"]) is list and all(type(n) is str and name_problem(n, folders=True) is None
                                                    for n in out["folders"]), "output folders")
        _check_files(out["read"])
    values = loads(second)
    _check(type(values) is list and len(values) == 3 and isinstance(values[0], Span)
           and _are_diagnostics(values[1])
           and (values[2] is None if out is None else _are_diagnostics(values[2])), "span and diagnostics")
    said: list[Diagnostic] = cast("list[Diagnostic]", values[1])
    _check(type(header["front"]) is int and 0 <= header["front"] <= len(said), "front end's diagnostics")
    header["span"], header["diagnostics"] = values[0], values[1]
    if out is not None:
        out["diagnostics"] = values[2]
    return header, program_json, robot_json


def _check(holds: bool, what: str) -> None:
    if not holds:
        raise BadValue(f"its {what} are not as kept")


def _rows(rows: Any, kinds: tuple[type | tuple[type, ...], ...]) -> bool:
    """Whether `rows` is a list of lists of len(kinds) items, each of its kind."""
    return type(rows) is list and all(
        type(row) is list and len(row) == len(kinds)
        and all(isinstance(v, k) and type(v) is not bool for v, k in zip(row, kinds, strict=True))
        for row in rows)


def _check_files(files: Any) -> None:
    _check(_rows(files, (str, (str, type(None)))), "files read")


def _are_diagnostics(value: Any) -> bool:
    return type(value) is list and all(type(d) is Diagnostic for d in value)


def _report(sink: Sink, diagnostics: list[Diagnostic]) -> None:
    for diagnostic in diagnostics:
        sink.report(diagnostic)


def _kept_diagnostics(diagnostics: list[Diagnostic]) -> list[Diagnostic]:
    """The diagnostics to say again when the build is reused."""
    return [d for d in diagnostics if d.code not in _OF_THE_CACHE]


def _digests(paths: list[Path], started: int) -> Files | None:
    """Each file with the digest of its bytes (None: it was looked for and not found); None when
    one cannot be read or may have changed after the build read it."""
    files: Files = []
    for dep in paths:
        try:
            st = os.stat(dep)
        except FileNotFoundError:
            files.append((str(dep), None))
            continue
        except OSError:
            return None
        tick = _COARSE_NS if st.st_mtime_ns % 1_000_000_000 == 0 else _FINE_NS
        if max(st.st_mtime_ns, st.st_ctime_ns) >= started - tick:
            return None
        try:
            files.append((str(dep), cache.file_digest(dep)))
        except OSError:
            return None
    return files


def _files_hold(files: Files) -> bool:
    """Whether each file has the bytes it had (or is still missing). Each is opened, so that a
    recorder around this build (`mpc run`'s) sees it as it saw the first build read it."""
    for file, digest in files:
        try:
            if digest is None:
                open(file, "rb").close()  # looked for as the build did: it is there now
                return False
            if cache.file_digest(Path(file)) != digest:
                return False
        except FileNotFoundError:
            if digest is not None:
                return False
        except OSError:
            return False
    return True


def _where(path: str) -> tuple[int, int, str]:
    """Which file a path leads to (device and inode, through any links) and what it is (a
    regular file, a folder, missing, other): a file swapped for a link, or a folder on its
    way swapped for one, leads to another file."""
    try:
        st = os.stat(path)
    except OSError:
        return 0, 0, "missing"
    kind = "file" if stat.S_ISREG(st.st_mode) else "folder" if stat.S_ISDIR(st.st_mode) else "other"
    return st.st_dev, st.st_ino, kind


def _distributions() -> list[str]:
    """The distributions installed beside mpc, with their versions (their dist-info folders)."""
    out: list[str] = []
    for folder in dict.fromkeys(interpreter_sites()):
        with contextlib.suppress(OSError):
            out += sorted(n for n in os.listdir(folder) if n.endswith(".dist-info"))
    return out
