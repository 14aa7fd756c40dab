"""kccd exports: one convex hull per body of a real UR5, covering its shapes; the settings
file; remove_joints and merge_additionally; the names an entry gives, checked."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import trimesh

from mpc.core.diagnostics import Severity
from tests.conftest import ERD, Diags, compile_file, write
from tests.fixtures import arm

UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"
HEAD = f"""
model:
  robotname: ur5
  modelname: ur5_model
  input_models: {{ur5: {{basefile: "{UR5}"}}}}
  assemble: {{model: ur5}}
  export_config:
"""
MISSING = ("urdf2kccd is not on PATH: wrote the hulls, {1}/{0}.urdf and {1}/{0}_kccd.yml; urdf2kccd "
           "would have made {1}/{0}.cfg and {0}Kinematics.cfg from them, and kccdcoveriv each body's "
           "fitted volume")


def build(tmp_path: Path, entries: str, diags: Diags, robot: str = "ur5", folder: str = "kccd") -> Path:
    out = compile_file(write(tmp_path / "m.yml", HEAD + entries), tmp_path / "out", diags).out
    assert out is not None, diags.summary()
    assert diags.take("W0520", Severity.WARNING).message == MISSING.format(robot, folder)
    return out


def hulls(out: Path) -> dict[str, trimesh.Trimesh]:
    files = sorted((out / "meshes/iv").glob("*.stl"))
    return {p.stem.removeprefix("collision_"): trimesh.load(p) for p in files}


def inside(hull: trimesh.Trimesh, points: np.ndarray) -> bool:
    """Every point on the inner side of every face plane of the convex `hull` (to 1e-7 m)."""
    normals = hull.face_normals
    offsets = (normals * hull.triangles[:, 0]).sum(axis=1)
    return bool((points @ normals.T - offsets <= 1e-7).all())


def test_one_convex_hull_per_body_covering_its_visuals(tmp_path: Path, diags: Diags) -> None:
    """Each UR5 body (world with base_link and base; each link below a revolute joint, wrist_3
    with ee_link and tool0) gets one closed convex hull, and it contains every vertex of the
    visual meshes of the links it stands for, where Pinocchio puts them at q = 0."""
    out = build(tmp_path, "    - {type: kccd}\n", diags)
    found = hulls(out)
    assert set(found) == {"world", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
                          "wrist_2_link", "wrist_3_link"}
    model = pin.buildModelFromUrdf(str(UR5))
    visuals = pin.buildGeomFromUrdf(model, str(UR5), pin.VISUAL, package_dirs=[str(ERD.parent.parent)])
    data, gdata = model.createData(), pin.GeometryData(visuals)
    pin.updateGeometryPlacements(model, data, visuals, gdata, pin.neutral(model))
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    settings = json.loads((out / "kccd/ur5_kccd.yml").read_text())
    covered = 0
    for body in settings["bodies"]:
        hull = found[body["link"]]
        assert hull.is_convex and hull.is_watertight and hull.is_volume, body["link"]
        oMb = data.oMf[model.getFrameId(body["link"])]
        for i, g in enumerate(visuals.geometryObjects):
            if model.frames[g.parentFrame].name not in body["links"]:
                continue
            mesh = trimesh.load(g.meshPath, force="mesh")
            points = (oMb.actInv(gdata.oMg[i]).homogeneous @ np.c_[mesh.vertices * g.meshScale,
                                                                   np.ones(len(mesh.vertices))].T).T[:, :3]
            assert inside(hull, points), body["link"]
            covered += 1
    assert covered == len(visuals.geometryObjects)


def test_the_kccd_urdf_carries_one_hull_per_body(tmp_path: Path, diags: Diags) -> None:
    """kccd/ur5.urdf: the UR5's kinematics, and each body's hull as its visual and collision."""
    out = build(tmp_path, "    - {type: kccd}\n", diags)
    model = pin.buildModelFromUrdf(str(out / "kccd/ur5.urdf"))
    assert model.nq == 6
    from lxml import etree

    root = etree.parse(str(out / "kccd/ur5.urdf")).getroot()
    for kind in ("visual", "collision"):
        meshes = {e.getparent().getparent().getparent().get("name"): e.get("filename")
                  for e in root.iterfind(f"link/{kind}/geometry/mesh")}
        assert meshes == {link: f"../meshes/iv/collision_{link}.stl" for link in hulls(out)}


def test_remove_joints_and_merge_additionally(tmp_path: Path, diags: Diags) -> None:
    """remove_joints merges wrist_3 into wrist_2 (the link goes); merge_additionally keeps
    wrist_1_joint but puts wrist_1's shapes into the forearm's hull."""
    out = build(tmp_path, """    - type: kccd
      remove_joints: [wrist_3_joint]
      merge_additionally: [wrist_1_joint]
""", diags)
    found = hulls(out)
    assert set(found) == {"world", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_2_link"}
    assert all(h.is_convex and h.is_watertight for h in found.values())
    model = pin.buildModelFromUrdf(str(out / "kccd/ur5.urdf"))
    assert [n for n in model.names][1:] == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                            "wrist_1_joint", "wrist_2_joint"]
    settings = json.loads((out / "kccd/ur5_kccd.yml").read_text())
    links = {b["link"]: b["links"] for b in settings["bodies"]}
    assert links["forearm_link"] == ["forearm_link", "wrist_1_link"]
    assert links["wrist_2_link"] == ["wrist_2_link", "ee_link", "tool0"]
    plain = build(tmp_path / "plain", "    - {type: kccd}\n", diags)
    assert found["forearm_link"].volume > hulls(plain)["forearm_link"].volume


@pytest.mark.parametrize(("reduce", "most"), [(100, lambda f: 100), (0.75, lambda f: int(np.ceil(f / 4)))])
def test_reduce_meshes_keeps_hulls_convex(tmp_path: Path, diags: Diags, reduce: float, most: Any) -> None:
    """reduce_meshes: a face budget, or (as in Phobos) the fraction of faces removed; the
    reduced hull is still one closed convex hull."""
    full = hulls(build(tmp_path / "full", "    - {type: kccd}\n", diags))
    reduced = hulls(build(tmp_path / "reduced", f"    - {{type: kccd, reduce_meshes: {reduce}}}\n", diags))
    assert set(full) == set(reduced)
    for link, hull in reduced.items():
        assert hull.is_convex and hull.is_watertight, link
        assert len(hull.faces) <= min(most(len(full[link].faces)), len(full[link].faces)), link


def test_settings_file(tmp_path: Path, diags: Diags) -> None:
    """The settings, exactly: the arm's base (a tetrahedron visual) and upper link (a box
    collision, used since it has no visual) are bodies; `lower` has no shape and no hull."""
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", """
model:
  robotname: arm
  modelname: arm-model
  input_models: {arm: {basefile: arm.urdf}}
  assemble: {model: arm}
  export_config:
    - type: kccd
      braking_model: {linearFactor: 0, invDeceleration: 0.02}
      simplify_swept_from: [upper]
      safety_distance: 0.01
      edit_collisions: {upper: {shape: box}}
      no_collision_between: {base: [lower]}
""")
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    assert diags.take("W0520", Severity.WARNING).message == MISSING.format("arm", "kccd")
    assert (out / "kccd/arm_kccd.yml").read_text() == """\
{
  "bodies": [
    {
      "link": "base",
      "links": [
        "base"
      ],
      "mesh": "../meshes/iv/collision_base.stl",
      "n_points": 25
    },
    {
      "link": "upper",
      "links": [
        "upper"
      ],
      "mesh": "../meshes/iv/collision_upper.stl",
      "n_points": 8
    }
  ],
  "braking_model": {
    "invDeceleration": 0.02,
    "latency": 0,
    "linearFactor": 0,
    "uncertainty": 0
  },
  "computation_budget": -1,
  "dont_check": [
    [
      "base",
      "upper"
    ]
  ],
  "max_approximation_order": 1,
  "order_0_joints": {
    "upper": [
      "elbow"
    ]
  },
  "report_up_to": 0,
  "robot": "arm",
  "safety_distance": 0.01,
  "urdf": "arm.urdf"
}
"""
    assert sorted(p.name for p in (out / "meshes/iv").iterdir()) == ["collision_base.stl",
                                                                      "collision_upper.stl"]
    box = trimesh.load(out / "meshes/iv/collision_upper.stl")
    assert np.allclose(box.bounds, [[-0.025, -0.025, -0.2], [0.025, 0.025, 0.2]])


def test_names_the_robot_does_not_have(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """    - type: kccd
      remove_joints: [wrist_3_link, elbow_jiont]
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    link, typo = diags.take_error("E0522"), diags.take_error("E0522")
    assert (link.message, link.hint) == (
        "kccd remove_joints names 'wrist_3_link', which is not a joint of the model",
        "give the joint above it, 'wrist_3_joint'")
    assert typo.message == "kccd remove_joints names 'elbow_jiont', which is not a joint of the model; " \
                           "did you mean 'elbow_joint'?"
    assert link.span.line == 7


def test_a_body_named_in_edit_collisions_must_be_one(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", HEAD + """    - type: kccd
      edit_collisions: {tool0: {n_points: 4}}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    assert diags.take_error("E0522").message == (
        "kccd edit_collisions names 'tool0', which is not a body (a link whose parent joint is movable) "
        "of the KCCD model")


def test_kccd_in_a_submodel(tmp_path: Path, diags: Diags) -> None:
    """A submodel's kccd export writes into the submodel's folder, for its links only."""
    out = build(tmp_path, """    - type: submodel
      name: wrist
      start: wrist_1_link
      export_config: [{type: kccd}]
""", diags, robot="wrist")
    assert set(hulls(out / "submodels/wrist")) == {"wrist_1_link", "wrist_2_link", "wrist_3_link"}
    assert (out / "submodels/wrist/kccd/wrist.urdf").is_file()


def test_a_nested_dirname_refers_to_the_hulls(tmp_path: Path, diags: Diags) -> None:
    """With `dirname: models/kccd` the URDF and the settings still point at the hulls."""
    out = build(tmp_path, "    - {type: kccd, dirname: models/kccd}\n", diags, folder="models/kccd")
    folder = out / "models/kccd"
    settings = json.loads((folder / "ur5_kccd.yml").read_text())
    assert all((folder / b["mesh"]).resolve().is_file() for b in settings["bodies"])
    assert settings["bodies"][0]["mesh"] == "../../meshes/iv/collision_world.stl"
    assert 'filename="../../meshes/iv/collision_world.stl"' in (folder / "ur5.urdf").read_text()


def test_the_settings_go_into_urdf2kccds_cfg(tmp_path: Path, diags: Diags) -> None:
    """Where urdf2kccd is installed, its `.cfg` gets the settings as Phobos writes them in:
    appended to the TITLE block, the BRAKINGMODEL template filled in, OVERWRITE lines, and
    DONTCHECK lines for the pairs (named by urdf2kccd's body names). The `.cfg` here is
    shaped as Phobos's reading of it expects; kccdcoveriv is not installed (W0520)."""
    from mpc.backends.kccd_tools import configured
    from mpc.core.span import Span
    from mpc.ir.program import KccdExport

    cfg = ("TITLE arm\n\n# BRAKINGMODEL <linearFactor> <invDeceleration> UNCERTAINTY <uncertainty> "
           "LATENCY <latency>\n\n# OVERWRITE\n\n"
           "BODY B_base MOVESWITH J_root a b c d ../../meshes/iv/collision_base.iv\nBODYPOINT 0 0 0\n\n"
           "BODY B_upper MOVESWITH J_shoulder a b c d ../../meshes/iv/collision_upper.iv\nBODYPOINT 0 0 0\n")
    settings = {"safety_distance": 0.01, "report_up_to": 0, "computation_budget": -1,
                "max_approximation_order": 1,
                "braking_model": {"linearFactor": 0, "invDeceleration": 0.02, "uncertainty": 0, "latency": 0},
                "order_0_joints": {"upper": ["elbow"]}, "dont_check": [["base", "upper"]],
                "bodies": [{"link": "base", "n_points": 25}, {"link": "upper", "n_points": 8}]}
    export = KccdExport(span=Span("m.yml", 1, 1, 1, 2))
    assert configured(cfg, settings, export, tmp_path, diags) == """
TITLE arm
SAFETYDISTANCE 0.01
REPORTUPTO 0
COMPUTATIONBUDGET -1
MAXAPPROXIMATIONORDER 1

BRAKINGMODEL 0 0.02 UNCERTAINTY 0 LATENCY 0

# OVERWRITE
OVERWRITE elbow WITH ORDER 0 END

BODY B_base MOVESWITH J_root a b c d ../meshes/iv/collision_base.iv
BODYPOINT 0 0 0

BODY B_upper MOVESWITH J_shoulder a b c d ../meshes/iv/collision_upper.iv
BODYPOINT 0 0 0

DONTCHECK B_base WITH B_upper END
"""
    assert diags.take("W0520", Severity.WARNING).message == (
        "kccdcoveriv is not on PATH: the bodies keep the points urdf2kccd gave them, without a fitted volume")


def test_two_kccd_exports_with_different_hulls(tmp_path: Path, diags: Diags) -> None:
    """Both write meshes/iv/collision_<link>.stl (Phobos's layout), so they must agree."""
    spec = write(tmp_path / "m.yml", HEAD + """    - {type: kccd}
    - {type: kccd, dirname: reduced, reduce_meshes: 0.5}
""")
    assert compile_file(spec, tmp_path / "out", diags).out is None
    diags.take("W0520", Severity.WARNING)
    assert diags.take_error("E0525").message == \
        "two kccd exports write different hulls to meshes/iv/collision_world.stl"
    assert not (tmp_path / "out").exists()
