"""Packages are found as rospack and ament find them: by the `<name>` of their package.xml, in
ROS_PACKAGE_PATH (crawled), AMENT_PREFIX_PATH and the folders above the model; a package folder
the environment names is read wherever its link points; a package not found is one error."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from mpc.compiler.driver import Options
from mpc.compiler.front_end import check_file
from mpc.core.packages import PackageResolver, crawl
from tests.conftest import Diags, compile_file, definition, write
from tests.fixtures import ARM_URDF, tetra_stl
from tests.mpc_command import mpc

PACKAGED_URDF = ARM_URDF.replace("meshes/tetra.stl", "package://arm_description/meshes/tetra.stl")


def _package(folder: Path, name: str) -> Path:
    """A package `name` in `folder` (of another name, maybe): its package.xml and a mesh."""
    write(folder / "package.xml", f"""
        <?xml version="1.0"?>
        <!-- <name>not_this</name>: a comment names nothing -->
        <package format="3">
          <name>{name}</name>
          <version>1.0.0</version>
        </package>
        """)
    tetra_stl(folder / "meshes/tetra.stl")
    return folder


def test_ros_package_path_is_crawled_for_package_xml_names_as_rospack_does(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    src = tmp_path / "ws/src"
    clone = _package(src / "group/arm_description-master", "arm_description")
    _package(clone / "test/inner", "inner")  # below a package: not a package of the path
    for marker in ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE"):  # sorted before `group`
        _package(src / f"a_{marker.lower()}/arm_description", "arm_description")
        (src / f"a_{marker.lower()}" / marker).touch()
        _package(src / f"a_{marker.lower()}/ignored_{marker.lower()}", f"ignored_{marker.lower()}")
    _package(src / ".hidden/arm_description", "arm_description")
    _package(src / "other/named_otherwise", "other_description")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(src))
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    resolver = PackageResolver()
    assert resolver.find("arm_description") == clone
    assert resolver.find("other_description") == src / "other/named_otherwise"
    assert resolver.find("named_otherwise") is None  # neither its name nor a folder of the path's
    assert resolver.find("inner") is None
    assert crawl(src) == {"arm_description": clone, "other_description": src / "other/named_otherwise"}


def test_a_clone_under_another_name_on_ros_package_path_compiles(tmp_path: Path) -> None:
    clone = _package(tmp_path / "ws/src/arm_description-master", "arm_description")
    write(tmp_path / "models/arm.urdf", PACKAGED_URDF)
    spec = write(tmp_path / "models/model.yml", definition("arm.urdf", "stl", "arm"))
    env = {**os.environ, "ROS_PACKAGE_PATH": str(tmp_path / "ws/src"), "AMENT_PREFIX_PATH": ""}
    done = mpc("compile", spec, "-o", tmp_path / "out", env=env)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == (clone / "meshes/tetra.stl").read_bytes()


def test_the_folders_above_the_model_are_named_by_their_package_xml(tmp_path: Path) -> None:
    """GitHub's archive of a description package unpacks as `<name>-master`: its model finds
    its own meshes by the package's name."""
    clone = _package(tmp_path / "arm_description-master", "arm_description")
    write(clone / "urdf/arm.urdf", PACKAGED_URDF)
    spec = write(clone / "urdf/model.yml", definition("arm.urdf", "stl", "arm"))
    env = {**os.environ, "ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""}
    checked = mpc("check", spec, env=env)
    assert (checked.returncode, checked.stderr) == (0, "")
    done = mpc("compile", spec, "-o", tmp_path / "out", env=env)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == (clone / "meshes/tetra.stl").read_bytes()


def test_a_folder_above_the_model_named_like_a_package_opens_none_of_its_files(tmp_path: Path) -> None:
    """`package://NAME` also finds a folder above the model by its folder's name (old layouts),
    but only a package.xml makes it a package root: a model under `home/` cannot read
    `package://home/…` outside its project."""
    secrets = tmp_path / "home"
    tetra_stl(secrets / "secret.stl")
    write(secrets / "project/arm.urdf", ARM_URDF.replace("meshes/tetra.stl", "package://home/secret.stl"))
    spec = write(secrets / "project/model.yml", definition("arm.urdf", "stl", "arm"))
    env = {**os.environ, "ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""}
    done = mpc("compile", spec, "-o", tmp_path / "out", env=env)
    assert done.returncode == 1
    assert f"error[E0650]: mesh 'package://home/secret.stl' in link 'base' is not read: it is " \
           f"'{secrets / 'secret.stl'}', outside the project and the model's package roots" in done.stderr
    assert not (tmp_path / "out").exists()


def test_an_ament_prefix_share_folder_holds_packages_by_their_package_xml(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    prefix = tmp_path / "install"
    by_folder = _package(prefix / "share/arm_description", "arm_description")
    by_name = _package(prefix / "share/gripper-2.0", "gripper_description")
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    resolver = PackageResolver()
    assert (resolver.find("arm_description"), resolver.find("gripper_description")) == (by_folder, by_name)


def test_a_linked_package_folder_on_ros_package_path_is_read_as_with_package(tmp_path: Path) -> None:
    """The environment names the folder: it is a package root wherever its link points, as
    `--package arm_description=LINK` makes it one."""
    real = _package(tmp_path / "elsewhere/arm_description-1.2", "arm_description")
    (tmp_path / "ws/src").mkdir(parents=True)
    (tmp_path / "ws/src/arm_description").symlink_to(real)
    write(tmp_path / "models/arm.urdf", PACKAGED_URDF)
    spec = write(tmp_path / "models/model.yml", definition("arm.urdf", "stl", "arm"))
    env = {**os.environ, "ROS_PACKAGE_PATH": str(tmp_path / "ws/src"), "AMENT_PREFIX_PATH": ""}
    by_path = mpc("compile", spec, "-o", tmp_path / "out", "--force", env=env)
    assert by_path.returncode == 0, by_path.stderr
    assert (tmp_path / "out/meshes/stl/tetra.stl").read_bytes() == (real / "meshes/tetra.stl").read_bytes()
    by_option = mpc("compile", spec, "-o", tmp_path / "out2", "--force", "--package",
                    f"arm_description={tmp_path / 'ws/src/arm_description'}")
    assert by_option.returncode == 0, by_option.stderr


# Five meshes of three files in one package that cannot be found, one of a package that is found.
MISSING_URDF = """\
<?xml version="1.0"?>
<robot name="legs">
  <link name="base">
    <visual><geometry><mesh filename="package://gone_description/meshes/base.dae"/></geometry></visual>
    <collision><geometry><mesh filename="package://gone_description/meshes/base.dae"/></geometry></collision>
  </link>
  <joint name="hip" type="fixed"><parent link="base"/><child link="leg"/></joint>
  <link name="leg">
    <visual><geometry><mesh filename="package://gone_description/meshes/leg.dae"/></geometry></visual>
    <collision><geometry><mesh filename="package://gone_description/meshes/leg.stl"/></geometry></collision>
  </link>
  <joint name="knee" type="fixed"><parent link="leg"/><child link="foot"/></joint>
  <link name="foot">
    <visual><geometry><mesh filename="package://gone_description/meshes/leg.dae"/></geometry></visual>
    <collision><geometry><mesh filename="meshes/tetra.stl"/></geometry></collision>
  </link>
</robot>
"""

MISSING_MESSAGE = (
    "package 'gone_description' was not found (searched the package map, ROS_PACKAGE_PATH, "
    "AMENT_PREFIX_PATH, the Python environment and the folders above the model); 3 mesh files need "
    "it, the first mesh 'package://gone_description/meshes/base.dae' of a visual of link 'base'")


def _notes(d: object) -> list[tuple[tuple[int, int] | None, str]]:
    return [((span.line, span.col) if span else None, text) for span, text in d.notes]  # type: ignore[attr-defined]


@pytest.mark.parametrize("command", ["check", "compile"])
def test_a_package_not_found_is_one_error_naming_how_many_files_need_it(
        tmp_path: Path, diags: Diags, command: str) -> None:
    tetra_stl(tmp_path / "meshes/tetra.stl")
    source = write(tmp_path / "legs.urdf", MISSING_URDF)
    spec = write(tmp_path / "model.yml", definition("legs.urdf", "stl", "legs").replace(
        "export_config:", "export_config:\n    - {type: sdf, mesh_format: stl}"))
    if command == "check":
        check_file(spec, diags, Options())
    else:
        assert compile_file(spec, tmp_path / "out", diags).out is None
    d = diags.take_error("E0654")
    assert d.message == MISSING_MESSAGE
    assert (d.span.file, d.span.line, d.span.col) == (str(source), 4, 39)
    notes = _notes(d)
    assert notes[2] == (None, "and 2 more uses of package 'gone_description'")
    assert len(notes) == 3
    assert d.hint == ("map the package with --package gone_description=DIR, or put the folder that "
                      "holds it (its package.xml names it) on ROS_PACKAGE_PATH")
    assert notes[:2] == [  # in the model's order (visuals then collisions)
            ((5, 42), "also mesh 'package://gone_description/meshes/base.dae' of a collision of link 'base'"),
            ((9, 39), "also mesh 'package://gone_description/meshes/leg.dae' of a visual of link 'leg'")]


def test_a_fifo_named_package_xml_above_the_model_names_nothing_and_does_not_hang(tmp_path: Path) -> None:
    """Reading a FIFO would wait for a writer forever; a device or a folder is no package.xml."""
    os.mkfifo(tmp_path / "package.xml")
    (tmp_path / "models").mkdir()
    (tmp_path / "models/package.xml").mkdir()
    resolver = PackageResolver(search_path=[])
    assert resolver.find("arm_description", tmp_path / "models") is None
