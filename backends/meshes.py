"""Meshes of a robot → files in the output folder, with unique, stable names.

A mesh value is a source file plus a chain of mesh ops. Each distinct value goes to
`meshes/<format>/<basename>` (extension in lower case; `_mirrored` added for a
reflected mesh, as Phobos names them). Two different values with the same name are
told apart by a content hash in their names; a value used twice is written once.
A mesh without ops in the export's format is copied byte for byte; one with ops, or in
another format, is computed with trimesh (DAE through pycollada, with its unit).
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import re
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mpc.backends.missing_packages import unfound_packages
from mpc.backends.mujoco_meshes import READS, REFUSED, REPAIR_HINT, REWRITE, RULES, judge
from mpc.backends.mujoco_meshes import problem as mujoco_problem
from mpc.backends.mujoco_meshes import verdict as mujoco_verdict
from mpc.backends.plain_meshes import Job
from mpc.backends.smurf_forms import named_shapes
from mpc.core.cores import WORKERS, mesh_workers, shared
from mpc.core.diagnostics import Sink
from mpc.core.files import why_absent
from mpc.core.numbers import zero_small
from mpc.core.packages import package_of
from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.geometry import (
    GENERATED,
    ConvexHull,
    ConvexPart,
    JoinShapes,
    MaterialPart,
    Mesh,
    MeshOp,
    ReduceMesh,
    ReflectMesh,
    ScaleMesh,
    is_generated,
)
from mpc.ir.robot import Robot
from mpc.ir.tree import depth_first

if TYPE_CHECKING:
    from mpc.ir.program import MjcfExport, SdfExport, UrdfExport

KEEP_FORMAT = "input_type"
# Changes when the way meshes are computed changes, so old cache entries go unused (5: stable DAE).
ENGINE = "5"
WRITABLE = ("stl", "obj", "dae", "ply", "bobj")  # formats mpc writes, for meshes with ops
MeshKey = tuple[Path, tuple[MeshOp, ...]]


def key(mesh: Mesh) -> MeshKey:
    """The file and ops of a mesh; a mesh mpc makes from shapes (ir/geometry.py `is_generated`)
    has no file: its name stands for it, as a relative path (a file's path is absolute)."""
    if is_generated(mesh.source):
        return (Path(mesh.source.uri.removeprefix(GENERATED)), mesh.ops)
    assert mesh.source.path is not None
    return (mesh.source.path, mesh.ops)


def _made(path: Path) -> bool:
    """Whether a MeshKey's path names a mesh mpc makes from shapes (no file)."""
    return not path.is_absolute()


@record(slots=True)
class MeshUse:
    """A mesh and where the robot uses it: link name and element kind."""

    link: str
    element: str
    mesh: Mesh


def mesh_uses(robot: Robot) -> Iterator[MeshUse]:
    """Every mesh of the robot in canonical order (depth-first, visuals then collisions)."""
    for _, name in depth_first(robot):
        link = robot.links[name]
        for kind, items in (("visual", link.visuals), ("collision", link.collisions)):
            for item in items:
                if isinstance(item.geometry, Mesh):
                    yield MeshUse(name, kind, item.geometry)


# Extensions of the formats the language names; `mars_obj` is OBJ content (Phobos's intended
# axis change was never written), `bobj` is MARS's binary OBJ (core/bobj.py).
EXTENSIONS = {"stl": "stl", "obj": "obj", "dae": "dae", "mars_obj": "mars.obj", "ply": "ply", "bobj": "bobj"}


def plan(robot: Robot, mesh_format: str, sink: Sink, export_span: Span,
         mujoco: bool = False) -> dict[MeshKey, str] | None:
    """Map each mesh value to its path in the output (relative, `meshes/<fmt>/<name>`).

    A mesh in another format than the export's, or with ops, is computed with trimesh at
    `copy`; an unchanged one is copied. Reports meshes that cannot be found; None if any.
    mujoco: the meshes are MuJoCo's (an MJCF export): an unchanged file that MuJoCo would not
    read as it is, but would once written again, is written again as `<name>_mujoco`
    (backends/mujoco_meshes.py), beside the copy another export may make.
    """
    ok = True
    wanted: dict[MeshKey, str] = {}
    uses = list(mesh_uses(robot))
    collided = _collided(uses) if mujoco else set()
    if any(use.mesh.source.path is None for use in uses):  # a package not found: once each
        for diagnostic in unfound_packages(((u.link, u.element, u.mesh) for u in uses), export_span):
            if diagnostic not in sink.diagnostics:  # said once, not once per export
                sink.report(diagnostic)
            ok = False
    for use in uses:
        src = use.mesh.source
        span = use.mesh.span or export_span
        k = key(use.mesh) if src.path is not None or is_generated(src) else None
        if k is not None and _made(k[0]):
            fmt = "stl" if mesh_format == KEEP_FORMAT else mesh_format  # made by mpc: no format of its own
            stem = k[0].stem + _suffix(use.mesh.ops)
            wanted.setdefault(k, f"meshes/{fmt}/{stem}.{EXTENSIONS.get(fmt, fmt)}")
            continue
        if src.path is None:
            if package_of(src.uri) is None:  # else its package was not found (reported above)
                sink.error(span, "E0602", f"mesh '{src.uri}' of a {use.element} of link '{use.link}' "
                           f"cannot be found: {src.unresolved}")
                ok = False
            continue
        assert k is not None
        if k in wanted:
            continue
        if not src.path.is_file():
            sink.error(span, "E0602", f"mesh file '{src.path}' of a {use.element} of link "
                       f"'{use.link}' {why_absent(src.path)}")
            ok = False
            continue
        fmt = src.format if mesh_format == KEEP_FORMAT else mesh_format
        if fmt not in EXTENSIONS or (mesh_format == KEEP_FORMAT and use.mesh.ops and fmt not in WRITABLE):
            if mesh_format != KEEP_FORMAT:
                sink.error(export_span, "E0501", f"writing '{fmt}' meshes is not supported yet",
                           hint="stl, obj, dae, bobj and mars_obj are")
                return None
            fmt = "stl"  # a computed mesh whose own format trimesh cannot write
        stem = src.path.name.rsplit(".", 1)[0] + _suffix(use.mesh.ops)
        if mujoco and not use.mesh.ops and fmt == src.format and \
                _mujoco_verdict(src.path, k in collided) == REWRITE:
            stem += "_mujoco"
        wanted[k] = f"meshes/{fmt}/{stem}.{EXTENSIONS[fmt]}"
    if not ok:
        return None
    return _disambiguate(wanted)


_SUFFIXES = {ReflectMesh: "_mirrored", ConvexHull: "_hull", JoinShapes: "_joined", ReduceMesh: "_reduced",
             ScaleMesh: "_scaled"}


def _op_suffix(op: MeshOp) -> str:
    if isinstance(op, ConvexPart):
        return f"_part{op.index}"
    if isinstance(op, MaterialPart):
        return f"_material{op.index}"
    return _SUFFIXES[type(op)]


def _suffix(ops: tuple[MeshOp, ...]) -> str:
    return "".join(_op_suffix(op) for op in ops)


def _disambiguate(wanted: dict[MeshKey, str]) -> dict[MeshKey, str]:
    from mpc.core.cache import file_digest

    by_name: dict[str, list[MeshKey]] = {}
    for k, name in wanted.items():
        by_name.setdefault(name, []).append(k)
    out = dict(wanted)
    for name, keys in by_name.items():
        if len(keys) == 1:
            continue
        paths = {p for p, _ in keys}
        first = keys[0][0]
        digests = {k: _digest(k) for k in keys}  # each file read once for these and its own digest
        # The same bytes: by their digests, which a warm build knows without reading the files.
        if len(set(ops for _, ops in keys)) == 1 and not any(_made(p) for p in paths) and all(
                file_digest(first) == file_digest(p) for p in paths):
            continue
        stem, ext = name.rsplit(".", 1)
        for k in keys:
            out[k] = f"{stem}_{digests[k]}.{ext}"
    return out


def _collided(uses: list[MeshUse]) -> set[MeshKey]:
    """The meshes of collisions (whose convex hulls MuJoCo computes), of those found."""
    return {key(u.mesh) for u in uses
            if u.element == "collision" and (u.mesh.source.path is not None or is_generated(u.mesh.source))}


def _mujoco_verdict(path: Path, collision: bool) -> str:
    """backends/mujoco_meshes.py `verdict`; READS for a file that cannot be read (copying it
    says why)."""
    try:
        return mujoco_verdict(path, collision)
    except OSError:
        return READS


def _digest(k: MeshKey) -> str:
    """Ten hex digits of the source's bytes and the ops, which tell apart meshes of one name;
    remembered with the file's digest (core/cache.py), so that a warm build does not read them."""
    from mpc.core.cache import digest_with

    ops = repr(k[1]).encode()
    if _made(k[0]):
        return hashlib.sha256(str(k[0]).encode() + ops).hexdigest()[:10]
    return digest_with(k[0], f"name {k[1]!r}", ops, 10)


def copy(files: dict[MeshKey, str], out: Path, sink: Sink, export_span: Span,
         robot: Robot | None = None, mujoco: bool = False) -> bool:
    """Write each planned mesh into `out` (`contents`), leaving those already there. The digest
    and the origin of each one are noted (core/cache.note_written): keeping the build
    (compiler/build_cache.py) need not read it again, nor keep a copy of its own. mujoco: as
    `plan`'s."""
    from mpc.core.cache import file_digest, note_written
    from mpc.core.files import confined_files, copy_file

    # Written already (by another export of the build): asked without resolving the path, which
    # `confined_files` does for the files written, below; a name that is not inside the output
    # is never taken as written, and is refused there.
    entries: dict[str, tuple[str, Path]] = {}
    found, ok = contents(files, sink, export_span, robot,
                         lambda rel: not rel.startswith("/") and ".." not in rel.split("/")
                         and (out / rel).exists(), entries, mujoco)
    paths = confined_files(out, found)
    for rel, content in found.items():
        dest = paths[rel]
        dest.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            dest.write_bytes(content)
            note_written(dest, *entries[rel])
        else:
            digest = file_digest(content)  # the build depends on its bytes: hashed once
            copy_file(content, dest)  # a regular file, checked when the model was read
            note_written(dest, digest, content)
    return ok


def contents(files: dict[MeshKey, str], sink: Sink, export_span: Span, robot: Robot | None = None,
             skip: Callable[[str], bool] = lambda rel: False,
             entries_used: dict[str, tuple[str, Path]] | None = None, mujoco: bool = False,
             ) -> tuple[dict[str, bytes | Path], bool]:
    """What each planned mesh is, by its file name: the bytes of the result of its ops, or the
    source file to copy as it is; and whether none failed. A mesh that fails is reported and
    left out; one for which `skip(name)` holds is left out silently.

    Results are kept in a content-addressed cache (core/cache.py: `meshes/`), keyed by
    the source's bytes, the ops and the format, and computed in parallel (a process pool)
    when several are missing; a later build with the same inputs only reads them.
    robot: to name, in a diagnostic, the link and element that use a mesh that fails.
    entries_used: filled with the SHA-256 and the cache entry of each mesh given as bytes, by
    its file name. mujoco: as `plan`'s; a mesh MuJoCo refuses is reported (E0585 copied, E0588
    computed) and left out.
    """
    from mpc.core.cache import notes_file, read_entry, remove_entry, touch_entry
    from mpc.core.files import describe

    ok = True
    todo: dict[Path, Job] = {}
    entries: dict[Path, tuple[bytes, str]] = {}
    plan_: list[tuple[Path, str]] = []
    found: dict[str, bytes | Path] = {}
    uses = list(mesh_uses(robot)) if robot is not None else []
    users = {(key(u.mesh)): u for u in uses}
    collided = _collided(uses) if mujoco else set()

    def where(src: Path, ops: tuple[MeshOp, ...]) -> tuple[Span, str]:
        use = users.get((src, ops))
        return ((use.mesh.span or export_span) if use else export_span,
                f" of a {use.element} of link '{use.link}'" if use else "")

    def refused(src: Path, ops: tuple[MeshOp, ...], rel: str, why: str, hint: str) -> None:
        """E0588: the computed mesh `rel` is one MuJoCo refuses."""
        span, of = where(src, ops)
        sink.error(span, "E0588", f"mesh '{rel}'{of}, computed from '{src}' for MuJoCo, is one it "
                   f"refuses: {why}", hint=hint)

    for (src, ops), rel in sorted(files.items(), key=lambda kv: kv[1]):
        name = rel.rsplit("/", 1)[-1]
        as_is = not ops and name.lower().endswith("." + src.name.rsplit(".", 1)[-1].lower()) \
            and not name.endswith(".mars.obj")
        written = skip(rel)  # by another export of the build, from the same source and ops
        if written and not mujoco:
            continue
        if as_is:
            problem, hint = _copy_problem(src), REPAIR_HINT
            collision = (src, ops) in collided
            verdict = _mujoco_verdict(src, collision) if mujoco and problem is None else READS
            if verdict == REFUSED:
                problem, hint = mujoco_problem(src, collision)
            if problem is not None:
                span, of = where(src, ops)
                sink.error(span, "E0585", f"mesh '{src}'{of} cannot be copied into the build: {problem}",
                           hint=hint)
                ok = False
                continue
            if verdict == READS:
                if not written:
                    plan_.append((src, rel))
                continue
        if written:  # computed by the other export: MuJoCo's verdict on its cache entry
            entry = _cached_path(src, ops, os.path.splitext(name)[1])
            if refusal := _mujoco_refusal(entry, (src, ops) in collided):
                refused(src, ops, rel, *refusal)
                ok = False
            continue
        try:
            cached = _cached_path(src, ops, os.path.splitext(name)[1])
            data, bad, digest = read_entry(cached)
            if bad is not None:
                sink.warning(where(src, ops)[0], "W0650", f"the cache entry '{cached}' of mesh '{rel}' "
                             f"is unusable ({bad}); it is removed and computed again")
                remove_entry(cached)
        except OSError as e:
            sink.error(where(src, ops)[0], "E0652", f"mesh '{rel}': {describe(e, 'use the mesh cache')}")
            ok = False
            continue
        if data is None:
            todo[cached] = (src, ops, cached)
        else:
            entries[cached] = data, digest
            touch_entry(cached)
        plan_.append((cached, rel))
    problems = _compute(list(todo.values()))
    key_of = {rel: k for k, rel in files.items()}
    for source, rel in plan_:
        if source in problems:
            src, ops, _ = todo[source]
            span, of = where(src, ops)
            code, problem = problems[source]
            sink.error(span, code, f"cannot compute mesh '{rel}'{of} from '{src}': {problem}")
            ok = False
            continue
        if source in todo:
            data, bad, digest = read_entry(source)
            if data is None:  # written a moment ago: only a cache changed under us gets here
                sink.error(where(*todo[source][:2])[0], "E0652", f"mesh '{rel}': the cache entry "
                           f"'{source}' cannot be read back ({bad or 'it is gone'})")
                ok = False
                continue
            entries[source] = data, digest
        ignored = notes_file(source)
        src, ops = key_of[rel]
        if source in entries and ignored.is_file():  # the entry records what computing it ignored
            span, of = where(src, ops)
            sink.warning(span, "W0605", f"mesh '{src}'{of} has broken references, ignored to read "
                         f"its triangles: {'; '.join(ignored.read_text(encoding='utf-8').splitlines())}",
                         hint="the geometry is complete; only materials or textures are missing")
        if source in entries and mujoco and (
                refusal := _mujoco_refusal(source, (src, ops) in collided, entries[source][0])):
            refused(src, ops, rel, *refusal)
            ok = False
            continue
        if source in entries:
            found[rel], digest = entries[source]
            if entries_used is not None:
                entries_used[rel] = digest, source
        else:
            found[rel] = source
    return found, ok


def _mujoco_refusal(entry: Path, collision: bool, data: bytes | None = None) -> tuple[str, str] | None:
    """(why, hint) when MuJoCo refuses the mesh computed into the cache entry `entry` (its bytes
    `data`, read when not given) for a visual or a `collision`, else None. The verdict on an
    entry it reads is kept in the cache (`verdicts/mujoco-2/<entry's name>`: an entry's name is
    its content's), as `_copy_problem` keeps its own, so that a warm build does not look at
    every vertex again."""
    from mpc.core.cache import read_entry

    mark = _sound_mark(RULES.replace(" ", "-"), f"{entry.name}.collision" if collision else entry.name)
    if mark.is_file():
        return None
    if data is None:
        data = read_entry(entry)[0]
        if data is None:  # gone: the export that wrote the build's copy read it
            return None
    verdict, why, hint = judge(data, entry.suffix.lower(), collision)
    if verdict != READS:
        return why, hint
    _note_sound(mark)
    return None


def _sound_mark(kind: str, name: str) -> Path:
    """The file whose presence says the content `name` was judged sound by the rules `kind`
    (a verdict kept in the cache, as pipeline/verdicts.py keeps its own)."""
    from mpc.core.cache import cache_dir

    return cache_dir("verdicts") / kind / name


def _note_sound(mark: Path) -> None:
    with contextlib.suppress(OSError):  # a read-only cache: judged again next time
        mark.parent.mkdir(parents=True, exist_ok=True)
        mark.touch()


def _copy_problem(src: Path) -> str | None:
    """Why a mesh file copied as it is would be refused by the programs that load it, or
    None: a DAE must be well-formed XML and hold finite numbers (a STL or OBJ is read when
    it is converted, not when it is copied). The verdict on a file's content is kept in the
    cache (`verdicts/dae/`, as pipeline/verdicts.py keeps its own), so that a large DAE is
    parsed once, not by every build that copies it."""
    if src.suffix.lower() != ".dae":
        return None
    from lxml import etree

    from mpc.core.cache import file_digest
    from mpc.core.span import hardened_parser

    try:
        mark = _sound_mark("dae", file_digest(src))
        if mark.is_file():
            return None
        data = src.read_bytes()
        etree.fromstring(data, hardened_parser(huge=True))
    except etree.XMLSyntaxError as e:
        return f"it is not well-formed XML ({e.msg})"
    except OSError:
        return None  # copying it reports what cannot be read
    for m in _NOT_FINITE.finditer(data):
        if not math.isfinite(float(m[1])):
            line = data.count(b"\n", 0, m.start(1)) + 1
            return f"it holds a number that is not finite ('{m[1].decode()}', line {line})"
    _note_sound(mark)
    return None


# A word of an XML file that may be a number that is not finite: nan, inf, an exponent of
# three digits (1e999 overflows) or 309 digits before the point, between spaces, quotes or tags.
_NOT_FINITE = re.compile(rb"""(?:^|(?<=[\s"'>]))([-+]?(?:nan|inf(?:inity)?|\d*\.?\d+e\+?\d{3,}"""
                         rb"""|\d{309,}(?:\.\d*)?))(?=[\s"'<]|$)""", re.IGNORECASE)


def _cached_path(src: Path, ops: tuple[MeshOp, ...], suffix: str) -> Path:
    from mpc.core.cache import cache_dir, file_digest

    # The name too: an OBJ names its object after the file (mesh_source.entry_of). A mesh made
    # from shapes has no file: its ops are all of it.
    content = "made" if _made(src) else file_digest(src)
    digest = hashlib.sha256(f"{content}|{src.name}|{ENGINE}|{ops!r}|{suffix}".encode()).hexdigest()
    return cache_dir("meshes") / f"{digest}{suffix}"


Task = tuple[bool, list[Job]]  # by the plain path or not; its jobs


def _compute(jobs: list[Job]) -> dict[Path, tuple[str, str]]:
    """Materialise each job into its cache path; {cache path: (code, problem)} for those
    that failed. The jobs of one source go together: all of them by the plain path
    (backends/plain_meshes.py: one read of the file, no trimesh) when it takes each of them,
    else each by trimesh. Several groups run in a pool of processes, one per core, the
    distinct files side by side (a trimesh job parses once: mesh_source.read's single flight);
    plain groups of a few megabytes, here and in one forked child (backends/mesh_fork.py)."""
    if not jobs:
        return {}
    from mpc.backends.plain_meshes import plain

    groups: dict[Path, list[Job]] = {}
    for job in jobs:
        groups.setdefault(job[0], []).append(job)
    tasks: list[Task] = []
    for group in groups.values():
        if all(plain(src, ops, dest.suffix) for src, ops, dest in group):
            tasks.append((True, group))
        else:
            tasks.extend((False, [job]) for job in group)
    firsts: dict[Path, int] = {}
    order = sorted(range(len(tasks)), key=lambda i: (firsts.setdefault(tasks[i][1][0][0], len(firsts))
                                                    if tasks[i][1][0][0] not in firsts else len(tasks) + i))
    tasks = [tasks[i] for i in order]
    workers = min(len(tasks), mesh_workers())
    sizes = _plain_sizes(tasks)
    size = sum(sizes) if sizes is not None else LIGHT  # not all plain: the pool's
    from mpc.backends import mesh_worker
    from mpc.core import meanwhile

    if mesh_worker.active() and sizes is not None and size >= FORKED:  # beside the worker
        costs = _costs(tasks, sizes)
        mesh_worker.offer(_priced(tasks, costs))
        meanwhile.now()  # the build's work that needs no mesh, while the worker starts on these
        results = [_materialise_all(tasks[i]) for i in sorted(range(len(tasks)), key=costs.__getitem__)]
        mesh_worker.note_digests()
    elif workers < 2 or len(jobs) < 3 or size < FORKED:
        results = [_materialise_all(task) for task in tasks]
    elif sizes is not None and size < LIGHT:
        from mpc.backends.mesh_fork import beside_a_fork, may_fork

        if not shared() and may_fork():
            results = beside_a_fork(tasks, _costs(tasks, sizes), _materialise_all,
                                    lambda task: [dest for _, _, dest in task[1]])
        else:  # `mpc run`'s builds use the other cores already
            results = [_materialise_all(task) for task in tasks]
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        heavy = not all(is_plain for is_plain, _ in tasks)
        context = multiprocessing.get_context(_start_method(heavy))
        if context.get_start_method() == "forkserver" and heavy:  # its workers fork from one that has trimesh
            context.set_forkserver_preload(["mpc.ir.mesh_props"])
        with ProcessPoolExecutor(workers, mp_context=context, initializer=_environment,
                                 initargs=(dict(os.environ),)) as pool:
            results = list(pool.map(_materialise_all, tasks))
    return {dest: problem for found in results for dest, problem in found.items()}


# Bytes of source files the plain path reads faster in the build's own process, or beside one
# forked child (backends/mesh_fork.py), than a pool starts and feeds its workers (the 88-link
# assembly's 14 MB: 0.86× the wall time, bench/README.md); and below which the fork (about 2 ms)
# costs more than the half it takes over saves.
LIGHT = 32 * 2**20
FORKED = 2**20


def _costs(tasks: list[Task], sizes: list[int]) -> list[float]:
    """About what each plain task costs, for the order they are taken in: its bytes, three
    times over for a text format (a DAE's numbers are parsed, an STL's are read as they are),
    and a fixed part (reading, writing and hashing its files)."""
    return [size * (3 if jobs[0][0].suffix.lower() in (".dae", ".obj") else 1) + 2**17
            for (_, jobs), size in zip(tasks, sizes, strict=True)]


def _plain_sizes(tasks: list[Task]) -> list[int] | None:
    """The bytes of each task's source when all are the plain path's; None when some are not,
    or when MPC_MESH_WORKERS set to a number asks for the pool."""
    if os.environ.get(WORKERS, "").isdigit() or not all(is_plain for is_plain, _ in tasks):
        return None
    sizes = []
    for _, jobs in tasks:
        try:
            sizes.append(jobs[0][0].stat().st_size)
        except OSError:  # reading it reports the problem
            sizes.append(0)
    return sizes


def _materialise_all(task: Task) -> dict[Path, tuple[str, str]]:
    """The jobs of one source by the plain path (when `task` says so and the file is one it
    reproduces), else each by trimesh; {cache path: (code, problem)} for those that failed."""
    is_plain, jobs = task
    if is_plain:
        from mpc.backends.plain_meshes import materialise

        done = materialise(jobs)
        if done is not None:
            return done
    found = {job[2]: _materialise(*job) for job in jobs}
    return {dest: problem for dest, problem in found.items() if problem}


def likely_tasks(robots: list[Robot], exports: Sequence[Any]) -> list[tuple[list[Job], float]]:
    """The plain mesh jobs the exports will most likely ask of the input models' meshes, grouped
    by source, with their costs: each mesh as read, in each export's mesh format, when that is
    a conversion the plain path makes and its entry is not in the cache (mesh_worker.py: given
    to the worker ahead of the ops, which may change some of them)."""
    from mpc.backends.plain_meshes import plain

    formats = {fmt for e in exports if (fmt := getattr(e, "mesh_format", None)) is not None}
    formats |= {fmt for e in exports for fmt in getattr(e, "additional_meshes", ())}
    groups: dict[Path, dict[Path, Job]] = {}
    for robot in robots:
        for use in mesh_uses(robot):
            source, ops = use.mesh.source, use.mesh.ops
            src = source.path
            if src is None or _made(src) or not src.is_file():
                continue
            for mesh_format in sorted(formats):
                fmt = source.format if mesh_format == KEEP_FORMAT else mesh_format
                if (not ops and fmt == source.format) or fmt not in EXTENSIONS:
                    continue
                suffix = "." + EXTENSIONS[fmt].rsplit(".", 1)[-1]
                if not plain(src, ops, suffix):
                    continue
                try:
                    dest = _cached_path(src, ops, suffix)
                except OSError:
                    continue
                if not dest.exists():
                    groups.setdefault(src, {})[dest] = (src, ops, dest)
    tasks: list[Task] = [(True, list(jobs.values())) for jobs in groups.values()]
    sizes = _plain_sizes(tasks) or []
    if sum(sizes) < FORKED:
        return []
    return _priced(tasks, _costs(tasks, sizes))


def _priced(tasks: list[Task], costs: list[float]) -> list[tuple[list[Job], float]]:
    """The jobs of each task with its cost, as the worker takes them (mesh_worker.offer)."""
    return [(jobs, cost) for (_, jobs), cost in zip(tasks, costs, strict=True)]


def _start_method(heavy: bool = True) -> str:
    """fork, with trimesh imported once here for every worker when a job needs it (heavy);
    forkserver once MuJoCo is loaded (its GL context and threads must not be copied into a
    worker). The workers run only mesh code, which holds no lock of another thread across a fork."""
    import sys

    if "mujoco" in sys.modules:
        return "forkserver"
    if heavy:
        import mpc.ir.mesh_props  # noqa: F401  (trimesh, shared by the forked workers)

    return "fork"


def _environment(environ: dict[str, str]) -> None:
    """A worker's environment is the build's: a forkserver's workers inherit the one it was
    started with, and the cache folder (MPC_CACHE_DIR) may have changed since."""
    os.environ.clear()
    os.environ.update(environ)


def _materialise(src: Path, ops: tuple[MeshOp, ...], dest: Path) -> tuple[str, str] | None:
    """Apply `ops` to the mesh in `src` and keep it as the cache entry `dest`; (code, why not),
    or None. Done once across processes: one that finds `dest` locked waits, then uses it."""
    from mpc.core.cache import load_entry, single_flight
    from mpc.core.files import describe

    try:
        with single_flight(dest):
            if load_entry(dest)[0] is not None:
                return None  # another process made it while this one waited
            return _derive(src, ops, dest)
    except OSError as e:
        return "E0652", describe(e, "write the mesh cache entry")


def _derive(src: Path, ops: tuple[MeshOp, ...], dest: Path) -> tuple[str, str] | None:
    from mpc.core.cache import notes_file, store_entry, trace
    from mpc.core.files import write_atomic
    from mpc.ir.geometry import MeshSource
    from mpc.ir.mesh_props import MeshError, as_trimesh

    ignored: list[str] = []
    try:
        mesh = as_trimesh(Mesh(source=MeshSource(uri=str(src), path=src), ops=ops), scaled=False,
                          ignored=ignored)
    except MeshError as e:
        return "E0603", str(e)
    if len(mesh.faces) == 0:
        return "E0603", "it has no triangles after reading"
    trace(f"derive {dest.name}")
    if dest.suffix == ".bobj":
        from mpc.core import bobj

        data: bytes | str = bobj.dumps(mesh)
    else:
        data = mesh.export(file_type=dest.suffix[1:])  # `x.mars.obj` is written as OBJ
        if dest.suffix == ".dae":
            from mpc.core.collada import stable

            data = stable(data if isinstance(data, bytes) else data.encode())
    if ignored:  # written before the entry, so that an entry never lacks its record
        write_atomic(notes_file(dest), "".join(f"{line}\n" for line in sorted(set(ignored))))
    store_entry(dest, data if isinstance(data, bytes) else data.encode())
    return None


def write(robot: Robot, mesh_format: str, additional: tuple[str, ...], out: Path, sink: Sink,
          export_span: Span, mujoco: bool = False) -> dict[MeshKey, str] | None:
    """The meshes of an export (urdf, sdf, mjcf): those its file references, in `mesh_format`
    (their plan, or None after an error), then the same in each `additional` format
    (`additional_meshes`: written beside, referenced by nothing). mujoco: the file is an MJCF
    (`plan`)."""
    from mpc.core.profile import stage

    with stage("meshes"):
        files = plan(robot, mesh_format, sink, export_span, mujoco)
        if files is None or not copy(files, out, sink, export_span, robot, mujoco):
            return None
        for fmt in additional:
            extra = plan(robot, fmt, sink, export_span)
            if extra is None or not copy(extra, out, sink, export_span, robot):
                return None
        return files


def for_export(robot: Robot, export: UrdfExport | SdfExport | MjcfExport, out: Path,
               sink: Sink, mujoco: bool = False) -> tuple[Robot, dict[MeshKey, str]] | None:
    """Write the meshes of a urdf, sdf or mjcf export (`write`); the robot to write (numbers
    near zero made 0 with `enforce_zero`; every unnamed visual and collision named as the
    SMURF names it, `named_shapes`) and where each mesh went, or None after an error.
    mujoco: MuJoCo reads the meshes (`plan`)."""
    files = write(robot, export.mesh_format, export.additional_meshes, out, sink, export.span, mujoco)
    if files is None:
        return None
    return named_shapes(zero_small(robot) if export.enforce_zero else robot), files


def namer(files: dict[MeshKey, str], prefix: str) -> Callable[[Mesh], str]:
    """How a model file names each mesh: `prefix` and the mesh's path in the output."""
    return lambda mesh: prefix + files[key(mesh)]
