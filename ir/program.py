"""ir.Program: one model definition, lowered — inputs, ordered ops, exports.

The compiler's output and the input of the apply and emit phases. `mpc compile
--emit ir` prints it; the apply phase reads the inputs and runs the ops in order.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from pathlib import Path
from typing import Literal

from mpc.core.record import record
from mpc.core.span import Span
from mpc.ir.ops import Op
from mpc.ir.refs import JointRef, LinkRef


@record(slots=True, kw_only=True)
class RepoRef:
    """A model in a git repository: url, a commit (or branch), the file inside it."""

    git: str
    model_in_repo: str
    commit: str | None = None
    branch: str | None = None
    submechanisms_in_repo: str | None = None


@record(slots=True, kw_only=True)
class Input:
    """An input model.

    name: its key under `input_models`.
    kind: `basefile` (a model file), `derived_base` (another definition's output),
        `repo` (a model file in a git repository).
    path: the model file (basefile) or the other definition (derived_base); None for repo.
    repo: where a `repo` input comes from.
    is_human: whether every link is marked as human (exoskeleton models).
    smurf_data: whether the input keeps its SMURF data (motors, sensors, poses, annotations…);
        False for a derived_base under `inherit_smurf_properties: false` (ir/smurf_data.py).
    xacro_args: (name, value) of each argument a xacro model file is expanded with.
    xacro_env: the environment variables its xacro may read with `$(env)` and `$(optenv)`.
    span: the YAML value that names the source.
    """

    name: str
    kind: Literal["basefile", "derived_base", "repo"]
    path: Path | None
    span: Span
    repo: RepoRef | None = None
    is_human: bool = False
    smurf_data: bool = True
    xacro_args: tuple[tuple[str, str], ...] = ()
    xacro_env: tuple[str, ...] = ()


class ExportEntry:
    """The base of every export record: an `export_config` entry, or what mpc adds (the SMURF,
    the ROS package files, a post_processing command). Each is a record of its own fields; this
    says what every one has (`span`, its `type`) and the defaults of what only some do, so that
    the driver asks any export the same questions."""

    __slots__ = ()
    span: Span
    type: str
    correct_inertials: bool = False  # make non-physical inertials physical first (URDF, SDF, MJCF)


@record(slots=True, kw_only=True)
class UrdfExport(ExportEntry):
    """A `type: urdf` entry of export_config.

    mesh_format: the format of the meshes it references (`input_type` keeps each
    mesh's own format).
    filename: the file's name without extension ("" for the robot's name), with
    `filename_suffix` appended.
    add_floating_base: hang the robot from a `world` link by a floating joint (ir/floating.py).
    additional_meshes: further formats the meshes are written in (not referenced).
    ros_package: when given, meshes are referenced as `package://<ros_package>/meshes/…`.
    enforce_zero: numbers closer to zero than 1e-12 are written as 0.
    link_in_smurf: the SMURF of its folder links this file (else lists it in additional_files).
    copy_package: when set (`copy_with_other_pathes`), also write the file with the other kind
        of mesh paths: `<filename>_ros.urdf` with `package://<copy_package>/…` paths, or, when
        the file has package paths, `<filename>_relpath.urdf` with relative ones.
    correct_inertials: non-physical inertials are made physical first (ir/physical.py).
    float_formats: (attribute or `default`, printf format) of `float_fmt_dict`
        (backends/float_formats.py); none: every number in its shortest exact form.
    span: the export_config entry.
    """

    mesh_format: str
    span: Span
    filename: str = ""
    add_floating_base: bool = False
    additional_meshes: tuple[str, ...] = ()
    ros_package: str | None = None
    enforce_zero: bool = False
    submodel: str = ""
    link_in_smurf: bool = False
    copy_package: str = ""
    correct_inertials: bool = False
    float_formats: tuple[tuple[str, str], ...] = ()
    type: Literal["urdf"] = "urdf"


@record(slots=True, kw_only=True)
class SdfExport(ExportEntry):
    """A `type: sdf` entry: SDFormat `version`, meshes in `mesh_format`; `link_in_smurf`,
    `ros_package`, `additional_meshes`, `enforce_zero`, `copy_package` (`_ros.sdf`,
    `_relpath.sdf`), `correct_inertials` and `float_formats` (keyed by element) as for URDF."""

    mesh_format: str
    span: Span
    filename: str = ""
    add_floating_base: bool = False
    include_cut_joints: bool = False
    version: Literal["1.6", "1.7", "1.9"] = "1.9"
    submodel: str = ""
    link_in_smurf: bool = False
    ros_package: str | None = None
    additional_meshes: tuple[str, ...] = ()
    enforce_zero: bool = False
    copy_package: str = ""
    correct_inertials: bool = False
    float_formats: tuple[tuple[str, str], ...] = ()
    type: Literal["sdf"] = "sdf"


@record(slots=True, kw_only=True)
class MjcfExport(ExportEntry):
    """A `type: mjcf` entry: MuJoCo's format; meshes in `mesh_format` (stl or obj: MuJoCo
    reads no DAE); `additional_meshes`, `enforce_zero`, `correct_inertials` as for URDF, and
    `float_formats` keyed by MJCF attribute (`pos`, `quat`, `mass`, …). No package paths:
    MuJoCo cannot resolve them. actuators: what the joints without a motor get (motors,
    position, velocity, motor, none: backends/mjcf_actuation.py); scene: also write
    `<file>_scene.xml` (floor, light, sky) that includes the robot's file."""

    mesh_format: str
    span: Span
    filename: str = ""
    add_floating_base: bool = False
    submodel: str = ""
    correct_inertials: bool = False
    additional_meshes: tuple[str, ...] = ()
    enforce_zero: bool = False
    float_formats: tuple[tuple[str, str], ...] = ()
    actuators: Literal["motors", "position", "velocity", "motor", "none"] = "motors"
    scene: bool = False
    type: Literal["mjcf"] = "mjcf"


@record(slots=True, kw_only=True)
class UsdExport(ExportEntry):
    """A `type: usd` entry: OpenUSD with UsdPhysics (backends/usd.py). layout: `layered` (an
    interface layer with a payload of physics, materials and geometry layers) or `single` (one
    file); `add_floating_base` and `correct_inertials` as for URDF. Meshes are held in the
    USD itself."""

    span: Span
    filename: str = ""
    layout: Literal["layered", "single"] = "layered"
    add_floating_base: bool = False
    submodel: str = ""
    correct_inertials: bool = False
    type: Literal["usd"] = "usd"


@record(slots=True, kw_only=True)
class PdfExport(ExportEntry):
    """A `type: pdf` entry: the kinematic tree as a graph (Graphviz source and PDF)."""

    span: Span
    filename: str = ""
    add_floating_base: bool = False
    submodel: str = ""
    type: Literal["pdf"] = "pdf"


# The joint selections a `joint_limits` export may name instead of joints.
JOINT_SELECTIONS = ("ALL", "ACTIVE", "INDEPENDENT", "ACTUATED", "ABSTRACT")

# The render export's camera directions: (azimuth, elevation) in degrees of MuJoCo's free
# camera (the camera looks along azimuth, tilted by elevation); robots face +x (REP 103).
RENDER_VIEWS: dict[str, tuple[float, float]] = {
    "iso": (225.0, -25.0), "front": (180.0, 0.0), "side": (270.0, 0.0), "back": (0.0, 0.0),
    "top": (180.0, -89.0)}
RENDER_BACKGROUNDS: dict[str, tuple[float, float, float]] = {
    "white": (1.0, 1.0, 1.0), "black": (0.0, 0.0, 0.0), "grey": (0.5, 0.5, 0.5), "gray": (0.5, 0.5, 0.5)}


@record(slots=True, kw_only=True)
class RenderExport(ExportEntry):
    """A `type: render` entry: PNG pictures in `render/<pose>_<view>.png`, drawn headless by
    MuJoCo (backends/render.py).

    views: camera directions (backends/scene.py VIEWS). geometry: visual, collision or both.
    poses: pose names; `zero` is every joint at 0, ("all",) the zero pose and every named one.
    size: (width, height) in pixels. background: rgb in 0..1.
    """

    span: Span
    views: tuple[str, ...] = ("iso", "front", "side")
    geometry: Literal["visual", "collision", "both"] = "visual"
    poses: tuple[str, ...] = ("all",)
    size: tuple[int, int] = (640, 480)
    background: tuple[float, float, float] = (1.0, 1.0, 1.0)
    add_floating_base: bool = False
    submodel: str = ""
    type: Literal["render"] = "render"


@record(slots=True, kw_only=True)
class JointLimitsExport(ExportEntry):
    """A `type: joint_limits` entry: `joints` (ALL, ACTIVE, INDEPENDENT, ACTUATED, ABSTRACT or
    names), written to `file_name`. joints_of: the submodel whose movable joints are listed
    (`joints: <submodel name>`); the file is still written where the entry stands."""

    span: Span
    joints: tuple[str, ...] = ("ALL",)
    file_name: str = "joint_limits.yml"
    add_floating_base: bool = False
    submodel: str = ""
    joints_of: str = ""
    type: Literal["joint_limits"] = "joint_limits"


@record(slots=True, kw_only=True)
class SubmodelExport(ExportEntry):
    """A `type: submodel` entry: the part of the robot that the exports naming it (their
    `submodel` field) write, into `submodels/<name>/` (ir/submodel.py).

    start: its root ("" : the robot's root). stop: the links (names, or regular expressions
    matched against whole names) where it ends ("()": the leaves); only the links on the way
    from start to a stop are kept, and with include_unstopped_branches also the branches
    that reach no stop. add_floating_base: as for the other exports.
    remove_joints: joints (names, or regular expressions matched against whole names) whose
    child links merge into their parents (ir/merge.py); remove_fixed: every fixed joint too.
    abstract_model: keep only the fixed joints and the submechanisms' independent ones (and
    the exoskeletons' dependent ones), merging the rest; the submechanisms go.
    no_submechanisms: the submodel has none. move_joint_axis_to_intersection: joint → the
    two joints whose axes' meeting point its frame moves to. name_replacements: (pattern,
    replacement) applied to every name last, after the merges.
    """

    span: Span
    name: str
    start: LinkRef = ""
    stop: tuple[str, ...] = ()
    include_unstopped_branches: bool = False
    add_floating_base: bool = False
    remove_joints: tuple[str, ...] = ()
    remove_fixed: bool = False
    abstract_model: bool = False
    no_submechanisms: bool = False
    move_joint_axis_to_intersection: Mapping[JointRef, tuple[JointRef, ...]] = field(default_factory=dict)
    name_replacements: tuple[tuple[str, str], ...] = ()
    type: Literal["submodel"] = "submodel"


@record(slots=True, kw_only=True)
class RosPackageExport(ExportEntry):
    """The ROS 2 package files (`package.xml`, `CMakeLists.txt`, `config/init_positions_*.yml`),
    added after the other exports when one of them writes `package://` paths.

    package: the package's name. version, description, license: the model's, when given.
    """

    span: Span
    package: str
    version: str = "0.0.0"
    description: str = ""
    license: str = ""
    type: Literal["ros_package"] = "ros_package"


@record(slots=True, kw_only=True)
class CommandExport(ExportEntry):
    """A `post_processing` command, run after the files are written (backends/commands.py).

    command: the program and its arguments; with `shell`, one string for the shell.
    cwd: where it runs, relative to the definition's folder ("" : the output folder).
    executable: the program to start instead of command[0] (with `shell`: the shell).
    env: the names of the variables of mpc's environment the command gets, besides PATH, HOME
        and the MPC_* folders (backends/commands.py).
    """

    span: Span
    command: tuple[str, ...]
    shell: bool = False
    cwd: str = ""
    executable: str = ""
    env: tuple[str, ...] = ()
    type: Literal["command"] = "command"


@record(slots=True, kw_only=True)
class SmurfExport(ExportEntry):
    """The SMURF of one output folder (the model's, or a submodel's): `smurf/<name>.smurf`
    and `smurf/<name>_<category>.yml` (backends/smurf.py). Always written.

    filename: the base name ("" : the robot's name).
    model_file: the URDF or SDF it links, relative to the output folder ("" : none).
    additional_files: (key, path relative to the output folder) of the other URDF/SDF files.
    description, version: the model's; version "" is left out.
    autogenerated: mark the files as generated (`mark_as_autogenerated`).
    add_floating_base: as the linked export, so that the names match its model.
    submodels: the submodels cut from this folder's robot, listed in `<name>_submodels.yml`.
    """

    span: Span
    filename: str = ""
    model_file: str = ""
    additional_files: tuple[tuple[str, str], ...] = ()
    description: str = ""
    version: str = ""
    autogenerated: bool = False
    add_floating_base: bool = False
    submodel: str = ""
    submodels: tuple[SubmodelExport, ...] = ()
    type: Literal["smurf"] = "smurf"


@record(slots=True, kw_only=True)
class KccdExport(ExportEntry):
    """A `type: kccd` entry: the collision model KCCD reads (backends/kccd.py).

    One convex hull per body: a link whose parent joint is movable and not in
    merge_additionally, with the shapes of the links hanging from it by fixed joints (or by
    merge_additionally joints), after remove_joints merged those joints' children.
    dirname: the folder of the KCCD URDF and configuration. join_before_convexhull: one hull
    of all shapes (else the union of one hull per shape). reduce_faces / reduce_ratio: a
    face budget, or the fraction of faces removed (Phobos's meaning here), 0: none.
    n_points, shapes: edit_collisions, per link. braking_model: linearFactor,
    invDeceleration, uncertainty, latency (empty: none given). no_collision_between: link →
    links never checked against it.
    """

    span: Span
    dirname: str = "kccd"
    join_before_convexhull: bool = True
    remove_joints: tuple[JointRef, ...] = ()
    merge_additionally: tuple[JointRef, ...] = ()
    keep_stls: bool = False
    keep_urdf: bool = False
    reduce_faces: int = 0
    reduce_ratio: float = 0.0
    n_points: Mapping[LinkRef, int] = field(default_factory=dict)
    shapes: Mapping[LinkRef, str] = field(default_factory=dict)
    braking_model: tuple[float, ...] = ()
    simplify_swept_from: tuple[LinkRef, ...] = ()
    safety_distance: float = 0.0
    report_up_to: float = 0.0
    computation_budget: float = -1.0
    max_approximation_order: int = 1
    no_collision_between: Mapping[LinkRef, tuple[LinkRef, ...]] = field(default_factory=dict)
    add_floating_base: bool = False
    submodel: str = ""
    type: Literal["kccd"] = "kccd"


# The exports that write a robot (the whole one or a submodel's), optionally floating.
RobotExport = (UrdfExport | SdfExport | MjcfExport | UsdExport | PdfExport | JointLimitsExport | SmurfExport
               | KccdExport | RenderExport)
Export = RobotExport | SubmodelExport | RosPackageExport | CommandExport


# -- the `test` section (checks/) ---------------------------------------------------------


@record(slots=True, kw_only=True)
class Tolerances:
    """Tolerances of the model tests: `mass` (kg), `distance` (m), `rad` (angles and, for
    lack of a better one, torques are measured against `default`)."""

    default: float = 0.01
    mass: float = 0.01
    rad: float = 0.03
    distance: float = 0.003


@record(slots=True, kw_only=True)
class CompareTarget:
    """The previous version of the model that the compare tests measure against.

    git: a repository (cloned); path: a folder or model file on disk (one of the two).
    branch, commit: what to check out (default: the repository's HEAD).
    model_in_repo: the model file in it; submechanisms_in_repo: its submechanisms file.
    ignore_failing_tests_for: a commit (prefix) of it at which failures become waivers.
    """

    span: Span
    git: str = ""
    path: Path | None = None
    branch: str = ""
    commit: str = ""
    model_in_repo: str = ""
    submechanisms_in_repo: str = ""
    ignore_failing_tests_for: str = ""


DENSITY = (100.0, 25000.0)  # kg/m³ a link may plausibly have: foam-filled shells to tungsten
FACTOR = 10.0  # how far a principal moment may be from its collision solid's at the same mass


@record(slots=True, kw_only=True)
class ModelTest:
    """One entry of `tests` (or of `hyrodynChecks`, then `dynamics`).

    name: the test's definition name. links: the links it names (compare_link_positions,
    symmetry checks). value: the expected figure (total_mass). plane: the mirror plane's
    normal (symmetry checks). angle, angles, joint_angles: the configuration that
    move_hyrodyn_model sets (one value for every joint, one per joint, or by joint name).
    as_error: physical_validity findings fail instead of warning. density: the range of
    plausible densities (kg/m³) and inertia_factor: how far principal moments may be from
    the collision solid's, for physical_validity. limit_tolerances: joint_limits's own
    bounds by figure (`position`, `velocity`, `effort`), where given. mirrored: the two name
    parts ("left", "right") whose swap names a joint's mirror image, for joint_limits.
    value is also a budget's limit (max_mesh_faces, max_mesh_bytes, max_collisions_per_link).
    """

    name: str
    span: Span
    dynamics: bool = False
    links: tuple[LinkRef, ...] = ()
    value: float | None = None
    plane: tuple[float, float, float] = (0.0, 1.0, 0.0)
    angle: float | None = None
    angles: tuple[float, ...] = ()
    joint_angles: Mapping[JointRef, float] | None = None
    as_error: bool = False
    density: tuple[float, float] = DENSITY
    inertia_factor: float = FACTOR
    limit_tolerances: Mapping[str, float] | None = None
    mirrored: tuple[str, str] | None = None


@record(slots=True, kw_only=True)
class TestPlan:
    """The lowered `test` section: the tests in order, tolerances, the compare model and
    the expected values of `test_data_file`."""

    __test__ = False  # not a pytest test class

    span: Span
    tests: tuple[ModelTest, ...] = ()
    tolerances: Tolerances = Tolerances()
    compare: CompareTarget | None = None
    expected_mass: float | None = None


@record(slots=True, kw_only=True)
class Program:
    """A lowered model definition.

    robotname, modelname: the robot's name in the files; the output's name.
    inputs: input models by name.
    ops: rewrites in order: loading and assembling parts, then editing the robot.
    exports: what to write.
    test: the model tests (checks/), when the definition has a `test` section.
    span: the definition's `model:` section.
    deployment: where the model goes (deploy/); None when the definition says nothing.
    """

    robotname: str
    modelname: str
    inputs: Mapping[str, Input]
    ops: tuple[Op, ...]
    exports: tuple[Export, ...]
    span: Span
    deployment: Deployment | None = None
    test: TestPlan | None = None


# -- deployment (deploy/) -------------------------------------------------------------------

@record(slots=True, kw_only=True)
class DeploySubmodule:
    """A `deployment.submodules` entry: a git submodule kept in the model's repository.

    repo: its address; a relative one (`../meshes.git`) is relative to the model repository's.
    target: its folder in the model repository. commit: the commit it is pinned to; else the
    newest commit of `branch` (None: the success branch).
    """

    repo: str
    target: str
    span: Span
    commit: str | None = None
    branch: str | None = None


@record(slots=True, kw_only=True)
class DeployMirror:
    """`deployment.mirror`: a second repository that gets a copy of the model's repository.

    branch: where the copy goes. submodules: keep submodules as submodules (else their files
    are copied in). merge_request: open one from `branch` into `mr_target`.
    """

    repo: str
    span: Span
    branch: str = "develop"
    submodules: bool = False
    merge_request: bool = False
    mr_mention: tuple[str, ...] | None = None
    mr_title: str | None = None
    mr_target: str | None = None


@record(slots=True, kw_only=True)
class Deployment:
    """The `deployment` section: where the built and tested model goes (deploy/).

    None (or an empty tuple for keep_files and submodules) means "not given", so that the
    pipeline's `default_deployment` fills it (a shallow merge, as Phobos does).
    do_not_deploy: build and test, but push nothing. mr_*: the merge request.
    keep_files: globs, relative to the repository, of files the update leaves alone.
    add_lfs_track: more file types tracked with git LFS (the model's own key, if given).
    """

    span: Span
    do_not_deploy: bool | None = None
    mr_target_branch: str | None = None
    mr_title: str | None = None
    mr_description: str | None = None
    mr_mention: tuple[str, ...] | None = None
    keep_files: tuple[str, ...] = ()
    submodules: tuple[DeploySubmodule, ...] = ()
    mirror: DeployMirror | None = None
    add_manifest: bool | None = None
    add_lfs_track: tuple[str, ...] | None = None
