"""A definition's last build, kept → the next `mpc compile` of it on the same inputs writes the
kept outputs, or starts at writing them.

A build is a function of what it reads. What the front end and the ops compute (compiler/
front_end.py: load, merge defaults, validate, lower, run the passes, read the inputs, apply
the ops) depends only on:
- mpc (its version with the digest of its sources, core/version.py), the Python running it
  and the distributions installed beside it (xacro, lxml, pydantic, trimesh shape results);
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
their bytes); exports that run other programs (`pdf`: Graphviz, `render`: EGL, `kccd`'s
tools, `post_processing` commands) make outputs that are not kept.

A kept build is used only when all of this is as it was, and its diagnostics are reported
again. Not kept: a build that failed (it runs again and says why again), one that fetched a
branch of a repository (what it holds changes on the remote), one whose files changed
while it ran, and the builds of `mpc run` (whose fingerprints skip whole models) and of
`mpc lsp` (which keeps its input models itself).

One entry per definition (its path as given and the working folder), replaced by its next
build, in `$MPC_CACHE_DIR/builds/`: a verified entry (core/cache.py) holding the
dependencies and, pickled apart so that a stale entry imports nothing, the program, the
robot and the diagnostics; beside it, a copy of the outputs, each file checked against its
SHA-256 when it is written out again. The cache is the user's own, as the mesh cache is.
"""

from __future__ import annotations

import contextlib
import copyreg
import hashlib
import io
import json
import os
import pickle
import shutil
import stat
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path, PosixPath, PurePath
from typing import TYPE_CHECKING, Any

from mpc.core import cache
from mpc.core.blas import user_environment
from mpc.core.diagnostics import Diagnostic, Sink
from mpc.core.packages import interpreter_sites
from mpc.core.reads import ReadRecorder, recording
from mpc.core.span import Span

if TYPE_CHECKING:  # the program and robot are pickled and unpickled, never imported here
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
# Exports whose files depend only on the program, the robot and the files mpc reads.
_KEPT_EXPORTS = frozenset({"urdf", "sdf", "smurf", "mjcf", "joint_limits", "submodel", "ros_package"})
# What a build says about the state of mpc's own cache (W0650: a damaged mesh entry, computed
# again), which the next build of the same inputs does not find: not said again.
_OF_THE_CACHE = frozenset({"W0650"})
# A file changed this close to the start of the build (or later) may have changed after the
# build read it, within one tick of the file system's clock: the build is not kept. File
# systems with whole-second times (FAT, some network ones) get two seconds.
_FINE_NS, _COARSE_NS = 20_000_000, 2_000_000_000

Files = list[tuple[str, str | None]]  # (path, SHA-256 of its bytes, or None: looked for, missing)


class KeptBuild:
    """One compilation's use of the build cache: the build kept for its definition (when all it
    depends on is as it was), and the recording of what this compilation reads."""

    def __init__(self, folder: Path, key: str, options: Options) -> None:
        self.folder, self.key, self.options = folder, key, options
        self.entry = folder / "entry"
        self.header: dict[str, Any] | None = None  # the kept build, its model's dependencies hold
        self.outputs_hold = False  # … and those of its outputs
        self.model_used = False  # this build took the kept program and robot
        self.recorder = ReadRecorder(ignore=[cache.cache_dir("")])  # derived data, commits' checkouts
        self.front_reads: int | None = None  # how many of the files recorded the front end opened
        self.started = time.time_ns()

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
        ])
        name = hashlib.sha256(json.dumps(where).encode()).hexdigest()
        kept = cls(cache.cache_dir("builds") / name[:2] / name, hashlib.sha256(key.encode()).hexdigest(),
                   options)
        if not options.force:
            kept._load()
        return kept

    # -- what is kept ----------------------------------------------------------------------------

    @property
    def modelname(self) -> str:
        assert self.header is not None
        return self.header["modelname"]

    @property
    def span(self) -> Span:
        assert self.header is not None
        return self.header["span"]

    def model(self) -> tuple[Program, Robot]:
        """The kept program and robot."""
        assert self.header is not None
        return pickle.loads(self.header["model"])

    def replay_model(self, sink: Sink) -> tuple[Program, Robot] | tuple[None, None]:
        """The kept program and robot, their diagnostics reported into `sink` again;
        (None, None) when `sink` makes one of them an error (--werror)."""
        assert self.header is not None
        self.model_used = True
        _report(sink, self.header["diagnostics"])
        return (None, None) if sink.has_errors() else self.model()

    def write_outputs(self, staging: Path) -> bool:
        """Copy the kept outputs into `staging`; False (nothing reported) when one is not the
        file that was kept. Raises OSError when `staging` cannot be written."""
        assert self.header is not None and self.outputs_hold
        kept = self.folder / self.header["outputs"]["folder"]
        for folder in self.header["outputs"]["folders"]:
            (staging / folder).mkdir(parents=True, exist_ok=True)
        for name, digest in self.header["outputs"]["files"]:
            try:
                data = (kept / name).read_bytes()
            except OSError:
                return False
            if hashlib.sha256(data).hexdigest() != digest:
                return False
            (staging / name).write_bytes(data)
        return True

    def replay_outputs(self, sink: Sink) -> None:
        """The diagnostics of the kept build, reported into `sink` again."""
        assert self.header is not None
        _report(sink, self.header["diagnostics"])
        _report(sink, self.header["outputs"]["diagnostics"])

    def drop_outputs(self) -> None:
        self.outputs_hold = False
        with contextlib.suppress(OSError):
            cache.remove_entry(self.entry)

    # -- keeping ---------------------------------------------------------------------------------

    @contextlib.contextmanager
    def recording(self) -> Iterator[None]:
        with recording(self.recorder):
            yield

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
        else:
            model_files = _digests(self.recorder.inputs(first=self.front_reads), self.started)
            if model_files is None:
                return
            buffer, paths = io.BytesIO(), list[PurePath]()
            try:
                _PathCollector(buffer, paths).dump((program, robot))
                diagnostics = _pickled(model_diagnostics)
            except (pickle.PicklingError, TypeError, AttributeError, RecursionError):
                return  # a value that cannot be kept: the next build runs in full
            opened = {f for f, _ in model_files}
            header = {"key": self.key, "files": model_files,
                      "named": [(p, *_where(p)) for p in sorted(set(map(str, paths)) - opened)],
                      "packages": sorted((p, n, f) for (p, n), f in self.recorder.packages.items()),
                      "model": buffer.getvalue(), "diagnostics": diagnostics,
                      "modelname": program.modelname, "span": program.span, "outputs": None}
        with contextlib.suppress(OSError):
            if out is not None and all(e.type in _KEPT_EXPORTS for e in program.exports):
                opened = {f for f, _ in header["files"]}
                header["outputs"] = self._keep_outputs(out, output_diagnostics, opened)
            self.folder.mkdir(parents=True, exist_ok=True)
            cache.store_entry(self.entry, pickle.dumps(header, protocol=pickle.HIGHEST_PROTOCOL))
            cache.trace(f"keep build {self.folder.name}")
            self._remove_old_outputs(header["outputs"])

    def _keep_outputs(self, out: Path, diagnostics: list[Diagnostic],
                      model_files: set[str]) -> dict[str, Any] | None:
        """A copy of the outputs in `out` (hard links where the cache is on the same file system:
        a file changed in place through one is found by its digest when it is written out)."""
        files = _digests([p for p in self.recorder.inputs() if str(p) not in model_files], self.started)
        if files is None:
            return None
        self.folder.mkdir(parents=True, exist_ok=True)
        copy = Path(tempfile.mkdtemp(prefix="outputs-", dir=self.folder))
        names, folders = [], []
        for here, dirs, found in os.walk(out):
            rel = Path(here).relative_to(out)
            for name in dirs:
                folders.append(str(rel / name))
                (copy / rel / name).mkdir()
            for name in found:
                source, target = Path(here) / name, copy / rel / name
                if source.is_symlink() or not source.is_file():
                    shutil.rmtree(copy, ignore_errors=True)
                    return None
                try:
                    os.link(source, target)
                except OSError:
                    shutil.copyfile(source, target)
                with open(target, "rb") as f:
                    names.append((str(rel / name), hashlib.file_digest(f, "sha256").hexdigest()))
        return {"folder": copy.name, "files": sorted(names), "folders": sorted(folders), "read": files,
                "diagnostics": _pickled(diagnostics)}

    def _remove_old_outputs(self, kept: dict[str, Any] | None) -> None:
        for folder in self.folder.glob("outputs-*"):
            if kept is None or folder.name != kept["folder"]:
                shutil.rmtree(folder, ignore_errors=True)

    # -- checking what is kept -------------------------------------------------------------------

    def _load(self) -> None:
        data, why = cache.load_entry(self.entry)
        if data is None:
            if why is not None:
                with contextlib.suppress(OSError):
                    cache.remove_entry(self.entry)
            return
        try:
            header = pickle.loads(data)
            if header["key"] != self.key or not _files_hold(header["files"]) or not self._names_hold(header):
                return
        except Exception:  # an entry of another make: unpickling it runs its classes' code
            return
        self.header = header
        outputs = header["outputs"]
        self.outputs_hold = outputs is not None and _files_hold(outputs["read"])
        cache.trace(f"reuse build {self.folder.name}" + (" with its outputs" if self.outputs_hold else ""))

    def _names_hold(self, header: dict[str, Any]) -> bool:
        if any(_where(p) != (dev, ino, kind) for p, dev, ino, kind in header["named"]):
            return False
        for package, near, found in header["packages"]:
            folder = self.options.resolver.find(package, Path(near) if near else None)
            if (str(folder) if folder is not None else None) != found:
                return False
        return True


def _report(sink: Sink, pickled: bytes) -> None:
    for diagnostic in pickle.loads(pickled):
        sink.report(diagnostic)


def _pickled(diagnostics: list[Diagnostic]) -> bytes:
    """The diagnostics to say again when the build is reused."""
    kept = [d for d in diagnostics if d.code not in _OF_THE_CACHE]
    return pickle.dumps(kept, protocol=pickle.HIGHEST_PROTOCOL)


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


class _PathCollector(pickle.Pickler):
    """Pickles, noting every path among the values: the files the program and robot name.
    Only paths go through Python (the pickler's dispatch table); everything else is pickled
    at C speed."""

    def __init__(self, file: io.BytesIO, paths: list[PurePath]) -> None:
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.paths = paths
        self.dispatch_table = {**copyreg.dispatch_table, PosixPath: self._path}

    def _path(self, path: PosixPath) -> Any:
        self.paths.append(path)
        return path.__reduce__()
