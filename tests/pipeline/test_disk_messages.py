"""The file a message names (issue 35.8): a full disk names the file that could not be
written, not the mesh it was copied from; an output folder with an immutable folder inside
says that its old copy stays, and where. Real mechanisms: a 200 KiB tmpfs and `chattr +i`,
which need root (these tests skip, saying so, without it)."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from tests.conftest import write
from tests.fixtures import arm
from tests.mpc_command import mpc as mpc_here
from tests.pipeline.helpers import mpc

MODEL = ("model:\n  robotname: arm\n  modelname: arm\n  input_models: {a: {basefile: arm.urdf}}\n"
         "  assemble: {model: a}\n  export_config:\n    - type: urdf\n      mesh_format: input_type\n")


def _project(folder: Path) -> Path:
    """The arm with a 1 MB STL (20,000 facets) and a pipeline of it; the pipeline file."""
    arm(folder)
    data = bytearray(b"mpc test: a large mesh".ljust(80, b" ")) + struct.pack("<I", 20000)
    for i in range(20000):
        data += struct.pack("<12fH", 0, 0, 0, 0, 0, 0, 0.1, 0, 0, 0, 0.01 * (i % 7 + 1), 0, 0)
    (folder / "meshes/tetra.stl").write_bytes(bytes(data))
    write(folder / "m.yml", MODEL)
    return write(folder / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions: [m.yml]\n")


def _root_only() -> None:
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs and chattr +i need root")


@contextmanager
def small_disk(folder: Path, size: str = "200k") -> Iterator[Path]:
    """A tmpfs of `size` mounted at `folder` for the block."""
    _root_only()
    folder.mkdir(parents=True)
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)], check=True)
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


@contextmanager
def immutable(folder: Path) -> Iterator[Path]:
    """`folder`, made immutable (chattr +i) for the block, and mutable again after it."""
    _root_only()
    folder.mkdir(parents=True, exist_ok=True)
    subprocess.run(["chattr", "+i", str(folder)], check=True)
    try:
        yield folder
    finally:
        for made in folder.parent.parent.glob(f"**/{folder.name}"):
            subprocess.run(["chattr", "-i", str(made)], check=False)


def test_a_full_disk_in_mpc_run_names_the_file_being_written(tmp_path: Path) -> None:
    pipeline = _project(tmp_path / "p")
    with small_disk(tmp_path / "disk") as disk:
        done = mpc("run", pipeline, "-o", disk / "build", cwd=tmp_path / "p", cache=tmp_path / "cache")
    assert done.returncode == 1
    assert (f"m.yml:1:1: error[E0660]: cannot write the output '{disk}/build/arm/meshes/stl/tetra.stl': "
            "No space left on device; the previous output is unchanged") in done.stderr
    assert f"'{tmp_path}/p/meshes" not in done.stderr


def test_a_full_disk_in_mpc_compile_names_the_file_being_written(tmp_path: Path) -> None:
    _project(tmp_path / "p")
    with small_disk(tmp_path / "disk") as disk:
        done = mpc_here("compile", tmp_path / "p/m.yml", "-o", disk / "out")
    assert done.returncode == 1
    assert (f"error[E0660]: cannot write the output '{disk}/out/meshes/stl/tetra.stl': No space left "
            "on device") in done.stderr


def test_an_immutable_folder_in_the_output_leaves_its_old_copy_with_a_warning(tmp_path: Path) -> None:
    _project(tmp_path)
    out = tmp_path / "out"
    assert mpc_here("compile", tmp_path / "m.yml", "-o", out).returncode == 0
    with immutable(out / "keep"):
        done = mpc_here("compile", tmp_path / "m.yml", "-o", out, "--force")
        assert done.returncode == 0, done.stderr
        old = next(tmp_path.glob(".out.mpc-old-*"))
        assert (f"warning[W0625]: the previous output, moved aside to '{old}', could not be removed "
                f"(cannot remove '{old}/keep': Operation not permitted); the new output is in place: "
                "remove the old one by hand (lsattr shows an immutable 'i' flag)") in done.stderr
        assert (out / "urdf/arm.urdf").is_file() and not (out / "keep").exists()
    shutil.rmtree(old)


def test_an_immutable_folder_in_a_run_s_output_is_said_too(tmp_path: Path) -> None:
    pipeline = _project(tmp_path)
    assert mpc("run", pipeline, cwd=tmp_path, cache=tmp_path / "cache").returncode == 0
    with immutable(tmp_path / "build/arm/keep"):
        done = mpc("run", pipeline, "--force", cwd=tmp_path, cache=tmp_path / "cache")
        assert done.returncode == 0, done.stderr
        old = next((tmp_path / "build").glob(".arm.mpc-old-*"))
        assert f"warning[W0625]: the previous output, moved aside to '{old}', could not be removed" \
            in done.stderr
    shutil.rmtree(old)
