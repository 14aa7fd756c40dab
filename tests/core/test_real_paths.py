"""Folders resolved through the folders resolved before (core/files.py `real_path`, `Roots`;
PackageResolver.resolved): the same answers as os.path.realpath and the read rule's own
comparison, whatever links, loops, `..` and missing parts a path holds."""

from __future__ import annotations

import os
from pathlib import Path

from mpc.core.files import Roots, _within, package_roots, real_path, resolved
from mpc.core.packages import PackageResolver


def _tree(tmp: Path) -> list[str]:
    """Folders and links of every kind a path may cross, and paths through them."""
    (tmp / "real" / "meshes").mkdir(parents=True)
    (tmp / "real" / "meshes" / "a.stl").write_bytes(b"solid\n")
    (tmp / "file").write_text("x")
    (tmp / "to_real").symlink_to(tmp / "real")  # absolute link
    (tmp / "real" / "up").symlink_to("..")  # relative link, upwards
    (tmp / "rel").symlink_to("real/meshes")  # relative link, downwards
    (tmp / "loop").symlink_to(tmp / "loop")  # a link to itself
    (tmp / "chain").symlink_to("to_real")  # a link to a link
    base = str(tmp)
    return [
        base, f"{base}/real", f"{base}/to_real", f"{base}/to_real/meshes", f"{base}/to_real/meshes/a.stl",
        f"{base}/real/up/to_real/meshes", f"{base}/rel", f"{base}/rel/a.stl", f"{base}/chain/meshes",
        f"{base}/loop", f"{base}/loop/x", f"{base}/missing/deeper", f"{base}/file/below",
        f"{base}/to_real/../file", f"{base}/to_real/./meshes", f"{base}//real", f"{base}/real/",
        "/", "relative/folder", ".", "",
    ]


def test_real_path_is_realpath(tmp_path: Path) -> None:
    paths = _tree(tmp_path)
    real_dirs: dict[str, str] = {}
    for _ in range(2):  # the second time from what the first kept
        for text in paths:
            assert real_path(text, real_dirs) == os.path.realpath(text), text
    assert package_roots(map(Path, paths[:12]), real_dirs) == package_roots(map(Path, paths[:12]))


def test_resolver_resolves_as_resolved(tmp_path: Path) -> None:
    resolver = PackageResolver(search_path=[])
    for text in _tree(tmp_path):
        assert resolver.resolved(Path(text)) == resolved(text), text


def test_roots_hold_what_within_says(tmp_path: Path) -> None:
    roots = [Path("/"), tmp_path / "real", tmp_path / "real" / "meshes", Path("/srv/a")]
    probes = [str(tmp_path / "real"), str(tmp_path / "real" / "x"), str(tmp_path / "realx"),
              str(tmp_path), "/srv/a", "/srv/a/b", "/srv/ab", "/srv", "/"]
    for chosen in (roots, roots[1:], roots[3:], []):
        held = Roots(chosen)
        for real in probes:
            assert held.hold(real) == any(_within(real, str(r)) for r in chosen), (chosen, real)


def test_a_mesh_outside_the_roots_is_refused_through_a_link(tmp_path: Path) -> None:
    """The read rule with the resolved folders kept: a link out of the package roots is refused
    after a file in the same folders was allowed."""
    package = tmp_path / "pkg"
    (package / "meshes").mkdir(parents=True)
    (package / "meshes" / "ok.stl").write_bytes(b"solid\n")
    secret = tmp_path / "secret"
    secret.mkdir()
    (secret / "key.stl").write_bytes(b"solid\n")
    (package / "meshes" / "leak.stl").symlink_to(secret / "key.stl")
    (package / "linked").symlink_to(secret)
    resolver = PackageResolver(search_path=[], package_map={"pkg": package})
    folder = resolver.resolved(package / "urdf")
    assert resolver.refusal(package / "meshes" / "ok.stl", folder) is None
    for leak in (package / "meshes" / "leak.stl", package / "linked" / "key.stl"):
        assert "outside the model's package roots" in (resolver.refusal(leak, folder) or "")


def test_a_located_file_is_its_folder_joined_with_what_the_model_wrote(tmp_path: Path) -> None:
    """locate gives the Path of pathlib's join of the whole, whatever slashes, dots and `..` the
    name holds, each time it is asked."""
    resolver = PackageResolver(search_path=[], package_map={"pkg": tmp_path / "pkg"})
    written = ["a.stl", "m/a.stl", "m/a.stl", "m/b.stl", "m//n/./a.stl", "m/../a.stl", "m/", "m/.",
               "/abs/a.stl", "//net/a.stl", "/", "", ".", "..", "m/n/", "./m/a.stl", "m/a.stl/"]
    for _ in range(2):
        for name in written:
            for uri, folder in ((f"package://pkg/{name}", tmp_path / "pkg"), (name, tmp_path / "urdf")):
                found, why = resolver.locate(uri, tmp_path / "urdf")
                assert (found, str(found), why) == (folder / name, str(folder / name), ""), uri


def test_the_roots_a_refusal_asks_for_follow_every_package_found_between_two_meshes(tmp_path: Path) -> None:
    """_package_roots answers from the folders known at each ask: a package found (or a model
    folder's parent) since the last mesh still counts."""
    for name in ("pkg", "other", "urdf"):
        (tmp_path / name / "meshes").mkdir(parents=True)
        (tmp_path / name / "meshes" / "a.stl").write_bytes(b"solid\n")
    (tmp_path / "pkg" / "meshes" / "to_other.stl").symlink_to(tmp_path / "other" / "meshes" / "a.stl")
    resolver = PackageResolver(search_path=[], package_map={"pkg": tmp_path / "pkg"})
    base = resolver.resolved(tmp_path / "pkg")
    leak = tmp_path / "pkg" / "meshes" / "to_other.stl"
    assert "outside the model's package roots" in (resolver.refusal(leak, base) or "")
    resolver.package_map["other"] = tmp_path / "other"
    assert resolver.refusal(leak, base) is None
    model = resolver.resolved(tmp_path / "urdf")  # a model folder: its parent is a root too
    assert resolver.refusal(tmp_path / "pkg" / "meshes" / "a.stl", model) is None
    assert resolver.refusal(tmp_path / "pkg" / "meshes" / "a.stl", model) is None
    fresh = PackageResolver(search_path=[], package_map=dict(resolver.package_map))
    for folder in (base, model, tmp_path):
        assert resolver._package_roots(folder) == fresh._package_roots(folder), folder
