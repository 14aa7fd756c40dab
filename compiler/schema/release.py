"""AST of `test` and `deployment`: how a model is checked and where it goes."""

from typing import Annotated, Any, ClassVar, Literal

from mpc.compiler.schema.base import ONE_OF, After, Expr, Node, OneOrMore
from mpc.core.diagnostics import did_you_mean

TESTS = frozenset({
    "topological_self_consistency", "process_double_check", "file_consistency", "load_in_pybullet",
    "compare_link_masses", "compare_link_transformations", "compare_amount_joints", "total_mass",
    "symmetry_check_masses", "hyrodynChecks", "physical_validity", "joint_limits", "max_mesh_faces",
    "max_mesh_bytes", "max_collisions_per_link", "effort_covers_gravity", "self_collision",
})
DYNAMICS_CHECKS = frozenset({
    "load_in_hyrodyn", "compare_masses", "compare_com", "compare_torques", "compare_link_positions",
    "symmetry_check", "symmetry_check_torques", "move_hyrodyn_model",
})


def _check_item(item: Any, names: frozenset[str], what: str) -> None:
    if isinstance(item, dict) and len(item) != 1:
        raise ValueError(f"a {what} with an argument is a mapping with one key, e.g. `- total_mass: 12.5`")
    name = item if isinstance(item, str) else next(iter(item)) if isinstance(item, dict) else None
    if not isinstance(name, str):
        raise ValueError(f"a {what} is a name or a mapping with one key, got {item!r}")
    if name not in names:
        raise ValueError(f"unknown {what} '{name}'{did_you_mean(name, names)}")


def _test_item(item: Any) -> Any:
    _check_item(item, TESTS, "test")
    if isinstance(item, dict) and "hyrodynChecks" in item:
        checks = item["hyrodynChecks"]
        if not isinstance(checks, list):
            raise ValueError("hyrodynChecks takes a list of dynamics checks")
        for check in checks:
            _check_item(check, DYNAMICS_CHECKS, "dynamics check")
    elif item == "hyrodynChecks":
        raise ValueError("hyrodynChecks takes a list of dynamics checks")
    return item


TestList = list[Annotated[str | dict[str, Any], ONE_OF, After(_test_item)]]


class Tolerances(Node):
    """Tolerances of the model tests; unset ones keep their defaults."""

    SECTION: ClassVar[str] = "tolerances"
    default: Expr = 0.01
    mass: Expr = 0.01
    rad: Expr = 0.03
    distance: Expr = 0.003


class CompareModel(Node):
    """The previous version of the model: in git (`git`) or on disk (`path`)."""

    SECTION: ClassVar[str] = "compare_model"
    ALIASES: ClassVar[dict[str, str]] = {"urdf_in_repo": "model_in_repo"}
    git: str | None = None
    path: str | None = None
    branch: str | None = None
    commit: str | None = None
    model_in_repo: str | None = None
    submechanisms_in_repo: str | None = None
    ignore_failing_tests_for: str | None = None


class TestSection(Node):
    SECTION: ClassVar[str] = "test"
    __test__ = False  # not a pytest test class
    tolerances: Tolerances | None = None
    compare_model: CompareModel | None = None
    tests: TestList = []
    test_data_file: str | None = None


class Submodule(Node):
    SECTION: ClassVar[str] = "a submodule"
    repo: str
    target: str
    commit: str | None = None
    branch: str | None = None


class MirrorDeployment(Node):
    SECTION: ClassVar[str] = "a deployment mirror"
    repo: str
    branch: str = "develop"
    submodules: bool = False
    merge_request: bool = False
    mr_mention: OneOrMore | None = None
    mr_title: str | None = None
    mr_target: str | None = None


class DeploymentSection(Node):
    SECTION: ClassVar[str] = "deployment"
    do_not_deploy: bool = False
    mr_target_branch: str | None = None
    mr_title: str | None = None
    mr_description: str | None = None
    mr_mention: OneOrMore | None = None
    keep_files: list[str] = []
    submodules: list[Submodule] = []
    mirror: MirrorDeployment | None = None
    add_manifest: bool | None = None
    add_lfs_track: OneOrMore | None = None


Forge = Literal["gitlab", "github", "none"]
