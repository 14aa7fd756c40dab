"""The figures physical_validity takes from collision meshes, kept in the cache, and the mesh
triangles read without trimesh: the same findings from a cold and a warm cache on real models,
a warm `mpc test` that imports no trimesh, a damaged entry computed again, and the triangles
equal to trimesh's on example-robot-data meshes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mpc.backends.urdf_reader import read
from mpc.checks import shape_figures
from mpc.checks.validity import findings
from mpc.core.cache import cache_dir
from mpc.core.diagnostics import Sink
from mpc.ir.bitmask import mesh_triangles
from mpc.ir.geometry import Mesh
from mpc.ir.mesh_props import as_trimesh
from tests.conftest import ERD

TALOS = ERD / "talos_data/robots/talos_full_v2.urdf"


def _findings(path: Path) -> list[tuple[str, str, str]]:
    robot = read(path, Sink())
    assert robot is not None
    return findings(robot, 0.003)


def test_a_warm_cache_gives_the_findings_a_cold_one_gives(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    cold = _findings(TALOS)
    robot = read(TALOS, Sink())
    assert robot is not None
    shapes = {shape_figures._key(c.geometry) for link in robot.links.values()
              if link.inertial is not None and link.inertial.mass > 0 for c in link.collisions}
    assert len(sorted(cache_dir("shapes").rglob("*.json"))) == len(shapes) == 40
    computed: list[object] = []
    real = shape_figures._computed
    monkeypatch.setattr(shape_figures, "_computed", lambda g: computed.append(g) or real(g))
    assert _findings(TALOS) == cold
    assert computed == []  # every figure came from the cache
    assert [code for _, code, _ in cold].count("W0710") == 3


def test_a_damaged_entry_is_computed_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    cold = _findings(TALOS)
    entry = sorted(cache_dir("shapes").rglob("*.json"))[0]
    entry.write_text('{"bounds": null, "closed": true, "volume": 1e9, "moments": [1, 1, 1]}')
    assert _findings(TALOS) == cold


def test_a_warm_mpc_test_imports_no_trimesh(tmp_path: Path) -> None:
    """physical_validity's figures from the cache, the bitmasks' and self-collision's shapes
    from the mesh arrays: a second `mpc test` of TALOS loads neither trimesh nor SciPy (0.5 s
    of imports); the first computed the figures with them."""
    definition = tmp_path / "talos.yml"
    definition.write_text(f"""
model:
  robotname: talos
  modelname: talos-model
  input_models: {{base: {{basefile: "{TALOS}"}}}}
  assemble: {{model: base}}
  collisions: {{auto_bitmask: true}}
  export_config: [{{type: urdf, mesh_format: stl}}]
  test:
    tests: [load_in_pybullet, self_collision, physical_validity]
""")
    environ = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}
    built = subprocess.run([sys.executable, "-m", "mpc.cli.main", "compile", str(definition), "-o",
                            str(tmp_path / "built")], env=environ, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    script = ("import sys\nfrom mpc.cli.main import main\n"
              f"code = main(['test', {str(definition)!r}, '--built', {str(tmp_path / 'built')!r}])\n"
              "print(code, 'trimesh' in sys.modules, 'scipy' in sys.modules)\n")
    first = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True, text=True)
    second = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True, text=True)
    assert first.stdout.split()[-3:] == ["0", "True", "True"], first.stderr  # it computed the figures
    assert second.stdout.split()[-3:] == ["0", "False", "False"], second.stderr


@pytest.mark.parametrize("relative", ["talos_data/meshes/v2/hip_z_collision.stl",
                                      "ur_description/meshes/ur5/collision/forearm.stl",
                                      "panda_description/meshes/collision/link4.stl"])
def test_the_triangles_read_without_trimesh_are_trimeshs(relative: str) -> None:
    from mpc.ir.geometry import MeshSource

    path = ERD / relative
    assert path.is_file()
    from mpc.ir.geometry import ReflectMesh, ScaleMesh

    mirrored = (ScaleMesh((1.0, 3.0, 1.0)), ReflectMesh(0))
    for scale, ops in ((None, ()), ((0.5, 2.0, 1.0), ()), ((-1.0, 1.0, 1.0), ()),
                       (None, (ReflectMesh(axis=1),)), ((2.0, 2.0, 2.0), mirrored)):
        mesh = Mesh(source=MeshSource(uri=str(path), path=path), scale=scale, ops=ops)
        vertices, faces = mesh_triangles(mesh)
        reference = as_trimesh(mesh)  # a reflection turns the triangles, on both sides alike
        expected = np.asarray(reference.vertices)[np.asarray(reference.faces)]
        assert np.array_equal(vertices[faces], expected)


def test_touching_pairs_are_kept_and_follow_a_changed_mesh(tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """auto_bitmask's touching pairs come from the cache the second time (no coal object made),
    the same pairs; a mesh file changed under the same name is tested again."""
    import shutil

    from mpc.ir import bitmask

    monkeypatch.setenv("MPC_CACHE_DIR", str(tmp_path / "cache"))
    robot = read(TALOS, Sink())
    assert robot is not None
    first = bitmask.touching(robot)
    assert len(first) > 20
    made: list[object] = []
    real = bitmask.coal_object
    monkeypatch.setattr(bitmask, "coal_object", lambda g, t=None: made.append(g) or real(g, t))
    assert bitmask.touching(robot) == first and made == []
    # the same robot whose torso collision mesh is now a copy of the head's, bigger: tested again
    link = robot.links["torso_2_link"]
    mesh = link.collisions[0].geometry
    assert isinstance(mesh, Mesh) and mesh.source.path is not None
    copy = tmp_path / "torso.stl"
    shutil.copyfile(mesh.source.path, copy)
    from dataclasses import replace

    moved = replace(robot, links={**robot.links, "torso_2_link": replace(link, collisions=(replace(
        link.collisions[0], geometry=replace(mesh, source=replace(mesh.source, path=copy))),))})
    assert bitmask.touching(moved) == first and made == []  # the same bytes: the same key
    copy.write_bytes(copy.read_bytes()[:84] + b"\0" * (len(copy.read_bytes()) - 84))  # its triangles gone
    changed = bitmask.touching(moved)
    assert made != [] and changed != first
