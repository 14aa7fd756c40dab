"""Every name a SMURF holds names an element of the model files beside it.

Phobos finds a shape's annotations (a bitmask after `auto_bitmask`, free keys) by the
shape's name in the model file the SMURF links, and fails with an UnboundLocalError on a
name the model file does not have. An unnamed shape is written with the name the SMURF
gives it (`<link>_collision`, `<link>_visual`, then `…1`, `…2`), in the URDF, the SDF and
the MJCF alike."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from lxml import etree

from mpc.compiler.driver import Options, compile_model
from tests.conftest import ERD, Diags, write

ROBOTS = {
    "ur5": ERD / "ur_description/urdf/ur5_robot.urdf",
    "talos": ERD / "talos_data/robots/talos_full_v2.urdf",
    "tiago": ERD / "tiago_description/robots/tiago.urdf",
}

DEFINITION = """\
model:
  robotname: {name}
  modelname: {name}-model
  input_models: {{base: {{basefile: "{basefile}"}}}}
  assemble: {{model: base}}
  collisions: {{auto_bitmask: true}}
  export_config:
    - {{type: urdf, mesh_format: stl, link_in_smurf: true}}
    - {{type: sdf, mesh_format: stl, correct_inertials: true}}
    - {{type: mjcf, mesh_format: stl, correct_inertials: true}}
"""


def smurf_names(smurf: Path) -> dict[str, set[str]]:
    """The names of each kind of element the SMURF's files name (links.yml's shape lists too)."""
    out: dict[str, set[str]] = {"link": set(), "joint": set(), "collision": set(), "visual": set()}
    for category, kind in (("links", "link"), ("joints", "joint"), ("collisions", "collision"),
                           ("visuals", "visual")):
        path = smurf.with_name(f"{smurf.stem}_{category}.yml")
        for entry in yaml.safe_load(path.read_text())[category]:
            out[kind].add(entry["name"])
            if category == "links":
                out["collision"].update(entry["collisions"])
                out["visual"].update(entry["visuals"])
    return out


def model_names(tree: etree._ElementTree, paths: dict[str, str]) -> dict[str, set[str]]:
    return {kind: {e.get("name") for e in tree.iterfind(path)} for kind, path in paths.items()}


URDF = {"link": "link", "joint": "joint", "collision": "link/collision", "visual": "link/visual"}
SDF = {"link": "model/link", "joint": "model/joint", "collision": "model/link/collision",
       "visual": "model/link/visual"}
MJCF = {"collision": ".//geom[@group='3']", "visual": ".//geom[@group='2']"}


@pytest.mark.long
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_every_name_in_the_smurf_is_an_element_of_each_model_file(name: str, tmp_path: Path,
                                                                   diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", DEFINITION.format(name=name, basefile=ROBOTS[name]))
    out = tmp_path / "out"
    compile_model(spec, diags, Options(out=out))
    assert not diags.has_errors(), diags.summary()
    diags.diagnostics.clear()
    names = smurf_names(out / "smurf" / f"{name}.smurf")
    assert names["collision"] and names["visual"]
    urdf = model_names(etree.parse(out / "urdf" / f"{name}.urdf"), URDF)
    sdf = model_names(etree.parse(out / "sdf" / f"{name}.sdf"), SDF)
    mjcf = model_names(etree.parse(out / "mjcf" / f"{name}.xml"), MJCF)
    # The SMURF links the URDF: every name it holds is there. The SDF and the MJCF name links
    # and joints by their formats' rules (`world`), and their shapes as the SMURF does.
    for kind, named in names.items():
        assert named <= urdf[kind], (kind, sorted(named - urdf[kind])[:5])
    for kind in ("collision", "visual"):
        assert names[kind] <= sdf[kind], (kind, sorted(names[kind] - sdf[kind])[:5])
        assert names[kind] <= mjcf[kind], (kind, sorted(names[kind] - mjcf[kind])[:5])
    # Every shape is named, in each file (none left to a reader's own naming).
    for tree, paths in ((urdf, URDF), (sdf, SDF), (mjcf, MJCF)):
        for kind in ("collision", "visual"):
            assert None not in tree[kind], (paths[kind], kind)
