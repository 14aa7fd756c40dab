"""What a computation in this process reads → recorded, so that its result can be fingerprinted.

Files are seen through an audit hook on `open` (a new reader cannot forget to declare its
inputs). What no file shows is noted by the code that looks it up: the folder each
`package://` name resolved to (core/packages.py), and anything that makes a result
depend on the day (a git branch fetched: `note_volatile`). Audit hooks cannot be removed,
so one hook serves the whole process and feeds the recorders that are active at the time;
with none active it costs a list check per `open`.

Not seen: the files read by other processes (`post_processing` commands, mesh workers).
"""

from __future__ import annotations

import contextlib
import itertools
import os
import re
import stat
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from mpc.core.files import real_path

# File types that are code, not inputs: modules imported while building.
_CODE_SUFFIXES = frozenset({".py", ".pyc", ".so", ".pyd", ".pth", ".pyi", ".typed", ".lark"})
_SYSTEM = ("/proc/", "/sys/", "/dev/", "/etc/")
# Installed distributions' metadata (their entry points, which libraries read for plugins): an
# editable install's `.egg-info` lies in the checkout, and a wheel built there rewrites it.
_METADATA = re.compile(r"\.(?:dist|egg)-info" + re.escape(os.sep))

_active: list[ReadRecorder] = []
_hooked = False


class ReadRecorder:
    """Records the files opened for reading, the packages looked up and the volatile inputs
    while it is active (`install`, or `with recording(...)`).

    ignore: folders whose files are not inputs (outputs, caches of derived data).
    """

    def __init__(self, ignore: Iterable[Path] = ()) -> None:
        self.ignore = tuple(str(p.resolve()) + os.sep for p in ignore)
        self.read: dict[str, None] = {}
        self.written: set[str] = set()
        self.packages: dict[tuple[str, str], str | None] = {}  # (package, near) → its folder
        self.volatile: list[str] = []  # why the result may differ with no file changed
        self.programs: dict[str, None] = {}  # files of the programs outputs were made with (`note_files`)
        # The Python installation holds code; its `share/` folders hold data (robot packages).
        prefixes = (sys.prefix, sys.base_prefix, sys.exec_prefix)
        self.code = tuple({os.path.realpath(p) + os.sep for p in prefixes})
        self.code_as_named = tuple({os.path.abspath(p) + os.sep for p in prefixes})

    def install(self) -> ReadRecorder:
        """Record from now on, for the life of the process (a worker of `mpc run`)."""
        _hook_once()
        _active.append(self)
        return self

    def opened(self, path: Any, mode: Any, flags: Any) -> None:
        if not isinstance(path, str | os.PathLike):
            return
        text = os.fspath(path)
        if not isinstance(text, str):
            return
        # open() gives a mode; os.open (tempfile, …) gives flags instead.
        writes = (any(c in mode for c in "wax+") if isinstance(mode, str)
                  else isinstance(flags, int) and bool(flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT)))
        if writes:
            self.written.add(os.path.abspath(text))
        else:
            self.read.setdefault(os.path.abspath(text))

    def inputs(self, first: int | None = None) -> list[Path]:
        """The files read that are inputs of the build (see the filters above); files that were
        looked for and not found included. first: only among the first so many files read; without
        it, the files of programs noted (`note_files`) too."""
        out = {Path(p) for p in self.programs} if first is None else set()
        real_dirs: dict[str, str] = {}  # the inputs' folders, resolved once (a model's meshes share them)
        for text in itertools.islice(self.read, first):
            if text in self.written or text.startswith(_SYSTEM) or text.startswith(self.ignore):
                continue
            if os.path.splitext(text)[1] in _CODE_SUFFIXES or f"{os.sep}__pycache__{os.sep}" in text \
                    or _METADATA.search(text):
                continue
            data = f"{os.sep}share{os.sep}" in text
            if text.startswith(self.code_as_named) and not data:
                continue  # no realpath for the many files read from the installation
            real = real_path(text, real_dirs)
            if real.startswith(self.code) and f"{os.sep}share{os.sep}" not in real:
                continue
            try:
                regular = stat.S_ISREG(os.stat(text).st_mode)
            except OSError:
                regular = True  # looked for and not found (or unreadable): an input all the same
            if regular:
                out.add(Path(text))
        return sorted(out)


@contextlib.contextmanager
def recording(recorder: ReadRecorder) -> Iterator[ReadRecorder]:
    """Record into `recorder` inside the block (and into the recorders active around it)."""
    _hook_once()
    _active.append(recorder)
    try:
        yield recorder
    finally:
        _active.remove(recorder)


def note_package(package: str, near: Path | None, found: Path | None) -> None:
    """A `package://` name was resolved (core/packages.py): part of what the result read."""
    for recorder in _active:
        recorder.packages[(package, str(near) if near is not None else "")] = \
            str(found) if found is not None else None


def note_files(paths: Iterable[str]) -> None:
    """Files a result depends on that it did not open: the programs it was made with
    (core/programs.py), libraries included; a path that does not exist is one looked for."""
    paths = tuple(paths)
    for recorder in _active:
        for path in paths:
            recorder.programs.setdefault(path)


def note_volatile(why: str) -> None:
    """The result depends on something no file shows (a branch fetched from a remote)."""
    for recorder in _active:
        recorder.volatile.append(why)


def _hook_once() -> None:
    global _hooked
    if not _hooked:
        _hooked = True
        sys.addaudithook(_hook)


def _hook(event: str, args: tuple[Any, ...]) -> None:
    if event == "open" and _active:
        for recorder in _active:
            recorder.opened(*args[:3])
